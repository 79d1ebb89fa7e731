"""A predictor that starts (again) asks the line for the part at its station, and each result
says where its part came from.

The line's recorder keeps the last part scanned at each station it records
(across its own restart) and answers a query of ``boltwatch/<st>/part``. A
predictor asks it in the background at start: a station whose line does not
answer yet starts at once, names no part (``unknown``) and asks again; the
line's answer is the part until a scan is heard (``restored``: the part may
have changed while the station was down); a scan always wins (``scanned``).
Over real zenoh on loopback: a router, the recorder, the line's PLC, an edge
predictor (pt1, on its acquisition) and a line predictor (pt2).
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
import zenoh

from services.predictor.edge_predictor import EdgePredictor
from services.predictor.served_station import ServedStation
from services.predictor.service import PredictorService
from services.predictor.station_runs import StationRuns
from shared.config import LoadedStation, load_line
from shared.contract import PartScan, TighteningResult, ToolState, channels, codec
from shared.runtime import ServiceSkeleton, Stop, declare_channel, zenoh_config
from tests.support.factories import part_scan, sample
from tests.support.listener import Listener
from tests.support.live_predictor import (
    PROGRAM_OF,
    START_NS,
    StationFeed,
    station_text,
    wait_for_subscriber,
)
from tests.support.live_recorder import RunningRecorder, wait_until
from tests.support.synthetic_runs import staircase

S = 1_000_000_000
ROWS = staircase().rows()[:200]  # a run's start: enough for a result, no decision needed
WAIT_S = 20.0  # a bound: a predictor asks the line again every few seconds


@pytest.fixture
def endpoint(router_endpoint: str) -> str:
    """The line's router (the services are its clients)."""
    return router_endpoint


@pytest.fixture
def stations(tmp_path: Path, endpoint: str) -> list[LoadedStation]:
    paths = []
    for station_id, program_id in PROGRAM_OF.items():
        path = tmp_path / f"{station_id}.toml"
        path.write_text(station_text(tmp_path, station_id, program_id, endpoint, connect=True))
        paths.append(path)
    return load_line(paths)


@pytest.fixture
def session(endpoint: str) -> Iterator[zenoh.Session]:
    """The test's own: the line's PLC, and what listens."""
    with zenoh.open(zenoh_config("client", connect=[endpoint])) as opened:
        yield opened


def scan(session: zenoh.Session, station_id: str, part_id: str) -> None:
    """The line's PLC: part ``part_id`` arrived at ``station_id``."""
    publisher = declare_channel(session, channels.PART, station_id)  # BLOCK, as the PLC's
    wait_for_subscriber(publisher)
    publisher.put(codec.encode(part_scan(part_id, station=station_id, time_ns=START_NS)))
    publisher.undeclare()


def line_part(session: zenoh.Session, station_id: str) -> str | None:
    """The part the line answers for ``station_id`` (None: no answer, or none known)."""
    for reply in session.get(channels.PART.key(station_id), timeout=2.0):
        if reply.ok is not None:
            return codec.decode(PartScan, reply.ok.payload.to_bytes()).part_id
    return None


def recorder_knows(session: zenoh.Session, station_id: str, part_id: str) -> None:
    wait_until(lambda: line_part(session, station_id) == part_id, f"the line knows {part_id}")


def test_a_scan_heard_wins_over_the_part_the_line_answers(
    stations: list[LoadedStation],
) -> None:
    runs = StationRuns(ServedStation(stations[0]))
    assert (runs.part_id, runs.part_source) == (None, "unknown")
    assert runs.restore_part(part_scan("OLD", station="pt1"))
    assert (runs.part_id, runs.part_source) == ("OLD", "restored")
    runs.on_part(part_scan("NEW", station="pt1"))
    assert not runs.restore_part(part_scan("OLD", station="pt1"))  # the line answered late
    assert (runs.part_id, runs.part_source) == ("NEW", "scanned")


def test_a_restarted_edge_predictor_asks_the_line_and_each_result_says_where_its_part_came_from(
    stations: list[LoadedStation], session: zenoh.Session
) -> None:
    published: list[object] = []
    lock = threading.Lock()

    def publish(message: object) -> None:
        with lock:
            published.append(message)

    def results() -> dict[int, tuple[str | None, str | None]]:
        with lock:
            found = [m for m in published if isinstance(m, TighteningResult)]
        return {m.run_id: (m.part_id, m.part_source) for m in found}

    station = stations[0]  # pt1: its acquisition hosts its predictor
    recorder = RunningRecorder(stations)
    try:
        scan(session, "pt1", "WHEEL-A")  # before the acquisition (re)starts
        recorder_knows(session, "pt1", "WHEEL-A")
    finally:
        recorder.finish()  # the line's recorder is down when the acquisition starts
    with ServiceSkeleton("acquisition") as skeleton:
        skeleton.open_session(station.config.zenoh)
        edge = EdgePredictor(skeleton, station, publish)  # starts without an answer
        skeleton.on_stop(Stop.WORK, edge.close)
        program = PROGRAM_OF["pt1"]

        def run(run_id: int) -> None:
            at_ns = START_NS + run_id * S
            edge.on_tool_state(ToolState("pt1", run_id, 3, program, "running", at_ns))
            for i, (t, torque, force, angle) in enumerate(ROWS):
                edge.on_sample(
                    sample(run_id, i, station="pt1", time_ns=at_ns + round(t * 1e9),
                           torque_nm=torque, force_n=force, angle_deg=angle)
                )  # fmt: skip
            edge.on_tool_state(ToolState("pt1", run_id, 3, program, "done", at_ns + S))

        run(1)  # the line has not answered: no part
        recorder = RunningRecorder(stations)  # back, with the part it kept
        try:
            wait_until(lambda: edge.runs.part_id == "WHEEL-A", "the line's answer", WAIT_S)
            run(2)
            scan(session, "pt1", "WHEEL-B")
            wait_until(lambda: edge.runs.part_id == "WHEEL-B", "the next part", WAIT_S)
            run(3)
        finally:
            recorder.finish()
    assert results() == {
        1: (None, "unknown"),
        2: ("WHEEL-A", "restored"),
        3: ("WHEEL-B", "scanned"),
    }


def test_a_restarted_line_predictor_gets_the_part_a_restarted_recorder_kept(
    stations: list[LoadedStation], session: zenoh.Session
) -> None:
    recorder = RunningRecorder(stations)
    try:
        scan(session, "pt2", "HUB-7")
        recorder_knows(session, "pt2", "HUB-7")
    finally:
        recorder.finish()
    recorder = RunningRecorder(stations)  # restarted: it answers from what it saved
    skeleton = ServiceSkeleton("predictor")
    stop = threading.Event()
    worker: threading.Thread | None = None
    try:
        skeleton.open_session(stations[1].config.zenoh)
        predictor = PredictorService(skeleton, [stations[1]])
        worker = threading.Thread(target=predictor.work, args=(stop,), daemon=True)
        worker.start()
        wait_until(lambda: predictor.part_ids["pt2"] == "HUB-7", "the line's answer", WAIT_S)
        with Listener(session, "pt2", (channels.RESULTS.topic,)) as heard:
            feed = StationFeed(session, "pt2")
            feed.state(5, PROGRAM_OF["pt2"], "running", START_NS)
            for i, row in enumerate(ROWS):
                feed.sample(5, i, row)
            feed.state(5, PROGRAM_OF["pt2"], "done", START_NS + S)
            (result,) = heard.wait_for(channels.RESULTS.topic, 1)
            feed.close()
    finally:
        stop.set()
        if worker is not None:
            predictor.wake()
            worker.join(10.0)
        skeleton.close()
        recorder.finish()
    assert (result.part_id, result.part_source) == ("HUB-7", "restored")
