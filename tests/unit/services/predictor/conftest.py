"""Fixtures of the predictor tests: a live predictor service on loopback."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
import zenoh

from services.predictor.service import PredictorService
from shared.config import LoadedStation, load_line
from shared.runtime import ServiceSkeleton, zenoh_config
from tests.support.live_predictor import PROGRAM_OF, station_text
from tests.support.live_recorder import free_port


@pytest.fixture
def endpoint() -> str:
    return f"tcp/127.0.0.1:{free_port()}"


@pytest.fixture
def router_endpoint() -> Iterator[str]:
    """A router of the line on loopback, its endpoint: every session of the test connects to
    it (peers reach each other through a router only as its clients, or as a peer and a
    client)."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    router = zenoh.open(zenoh_config("router", listen=[endpoint]))
    try:
        yield endpoint
    finally:
        router.close()


@pytest.fixture
def stations(tmp_path: Path, endpoint: str) -> list[LoadedStation]:
    paths = []
    for station_id, program_id in PROGRAM_OF.items():
        path = tmp_path / f"{station_id}.toml"
        path.write_text(station_text(tmp_path, station_id, program_id, endpoint))
        paths.append(path)
    return load_line(paths)


@pytest.fixture
def service(stations: list[LoadedStation]) -> Iterator[PredictorService]:
    skeleton = ServiceSkeleton("predictor")
    skeleton.own_session(zenoh.open(zenoh_config("peer", listen=stations[0].config.zenoh.listen)))
    stop = threading.Event()
    predictor = PredictorService(skeleton, stations)
    worker = threading.Thread(target=predictor.work, args=(stop,), daemon=True)
    worker.start()
    try:
        yield predictor
    finally:
        stop.set()
        predictor.wake()
        worker.join(5.0)
        skeleton.close()
    assert not worker.is_alive()
