"""Fixtures of the recorder tests: a station on loopback, a recorder in a thread, a publisher."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
import zenoh

from shared.config import LoadedStation, load_station
from shared.runtime import zenoh_config
from tests.support.live_recorder import RunningRecorder, free_port, write_station_file


@pytest.fixture
def endpoint() -> str:
    return f"tcp/127.0.0.1:{free_port()}"


@pytest.fixture
def station(tmp_path: Path, endpoint: str) -> LoadedStation:
    path = write_station_file(tmp_path / "station.toml", tmp_path / "recordings", listen=[endpoint])
    return load_station(path)


@pytest.fixture
def recorder(station: LoadedStation) -> Iterator[RunningRecorder]:
    running = RunningRecorder(station)
    try:
        yield running
    finally:
        running.finish()


@pytest.fixture
def publisher_session(endpoint: str, recorder: RunningRecorder) -> Iterator[zenoh.Session]:
    session = zenoh.open(zenoh_config("peer", connect=[endpoint]))
    try:
        yield session
    finally:
        session.close()
