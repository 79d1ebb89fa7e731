"""Each run's result names the part the line scanned before the run started: both placements.

The line predictor (one service for pt1 and pt2, over real zenoh) and the
edge predictor (on a station's acquisition, its part scans from zenoh) keep
the current part per station: a run takes the part current when it starts,
a part scanned during a run belongs to the next run, a station with no part
scanned names none, and one station's part never reaches another's results.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

import zenoh

from services.predictor.edge_predictor import EdgePredictor
from services.predictor.service import PredictorService
from shared.config import LoadedStation
from shared.contract import TighteningResult, ToolState, channels, codec, keys
from shared.runtime import ServiceSkeleton, Stop, declare_channel, zenoh_config
from tests.support.factories import part_scan, sample
from tests.support.listener import Listener
from tests.support.live_predictor import (
    PROGRAM_OF,
    START_NS,
    StationFeed,
    wait_for_subscriber,
    wait_for_token,
)
from tests.support.live_recorder import wait_until
from tests.support.synthetic_runs import staircase

S = 1_000_000_000
ROWS = staircase().rows()[:200]  # a run's start: enough for a result, no decision needed


class PartFeed:
    """The line's PLC of one station: its part scans on ``boltwatch/<st>/part``."""

    def __init__(self, session: zenoh.Session, station_id: str) -> None:
        self.station_id = station_id
        # as the line's PLC puts it (congestion control BLOCK): zenoh's default may drop a
        # put right after a burst of samples under load, and the scan is then never heard
        self.publisher = declare_channel(session, channels.PART, station_id)
        wait_for_subscriber(self.publisher)

    def scan(self, part_id: str, at_ns: int, station: str | None = None) -> None:
        message = part_scan(part_id, station=station or self.station_id, time_ns=at_ns)
        self.publisher.put(codec.encode(message))

    def close(self) -> None:
        self.publisher.undeclare()


def run(
    feed: StationFeed, run_id: int, at_ns: int, during: Callable[[], None] | None = None
) -> None:
    """Run ``run_id`` of ``feed``'s station: running, samples, done; ``during()`` halfway."""
    program = PROGRAM_OF[feed.station_id]
    feed.state(run_id, program, "running", at_ns)
    for i, row in enumerate(ROWS):
        if i == len(ROWS) // 2 and during is not None:
            during()
        feed.sample(run_id, i, row)
    feed.state(run_id, program, "done", at_ns + S)


def test_the_line_predictor_names_the_part_current_when_each_run_started(
    service: PredictorService, endpoint: str
) -> None:
    with (
        zenoh.open(zenoh_config("peer", connect=[endpoint])) as session,
        Listener(session, "*", (channels.RESULTS.topic,)) as heard,
    ):
        for station_id in PROGRAM_OF:
            wait_for_token(session, keys.health_key(station_id, "predictor"))
        pt1, pt2 = StationFeed(session, "pt1"), StationFeed(session, "pt2")
        plc = PartFeed(session, "pt1")
        run(pt1, 41, START_NS)  # no part scanned yet
        plc.scan("WHEEL-A", START_NS + 2 * S)
        wait_until(lambda: service.part_ids["pt1"] == "WHEEL-A", "part A at pt1", 10.0)

        def next_part_arrives() -> None:  # mid-run: it belongs to the next run
            plc.scan("WHEEL-B", START_NS + 4 * S)
            wait_until(lambda: service.part_ids["pt1"] == "WHEEL-B", "part B at pt1", 10.0)

        run(pt1, 42, START_NS + 3 * S, during=next_part_arrives)
        run(pt2, 42, START_NS + 3 * S)  # pt2's line scanned nothing: pt1's part is not its
        run(pt1, 43, START_NS + 6 * S)
        plc.scan("WHEEL-C", START_NS + 8 * S, station="pt2")  # names another station
        wait_until(lambda: service.bad_payloads == 1, "the stray scan counted", 10.0)
        heard.wait_for(channels.RESULTS.topic, 4)
        for feed in (pt1, pt2, plc):
            feed.close()
        results: list[TighteningResult] = heard.of(channels.RESULTS.topic)
    parts = {(result.station, result.run_id): result.part_id for result in results}
    assert parts == {
        ("pt1", 41): None,
        ("pt1", 42): "WHEEL-A",
        ("pt2", 42): None,
        ("pt1", 43): "WHEEL-B",
    }
    assert service.part_ids == {"pt1": "WHEEL-B", "pt2": None}  # the stray scan changed nothing
    assert service.counts["pt1"].bad_payloads == 1


def test_the_edge_predictor_hears_parts_on_zenoh_and_its_runs_name_them(
    stations: list[LoadedStation], endpoint: str
) -> None:
    published: list[object] = []
    lock = threading.Lock()

    def publish(message: object) -> None:
        with lock:
            published.append(message)

    def results() -> dict[int, str | None]:
        with lock:
            return {m.run_id: m.part_id for m in published if isinstance(m, TighteningResult)}

    station = stations[0]  # pt1, whose acquisition would host it
    with ServiceSkeleton("acquisition") as skeleton:
        skeleton.own_session(zenoh.open(zenoh_config("peer", listen=[endpoint])))
        edge = EdgePredictor(skeleton, station, publish)
        skeleton.on_stop(Stop.WORK, edge.close)
        with zenoh.open(zenoh_config("peer", connect=[endpoint])) as session:
            plc = PartFeed(session, "pt1")
            plc.scan("HEAD-1", START_NS)
            wait_until(lambda: edge.runs.part_id == "HEAD-1", "part 1 at the edge", 10.0)
            program = PROGRAM_OF["pt1"]
            for run_id, part_during in ((7, "HEAD-2"), (8, None)):
                at_ns = START_NS + run_id * S
                edge.on_tool_state(ToolState("pt1", run_id, 3, program, "running", at_ns))
                for i, row in enumerate(ROWS):
                    if i == len(ROWS) // 2 and part_during is not None:
                        plc.scan(part_during, at_ns + S // 2)
                        wait_until(lambda: edge.runs.part_id == "HEAD-2", "part 2", 10.0)
                    t, torque, force, angle = row
                    edge.on_sample(
                        sample(run_id, i, station="pt1", time_ns=at_ns + round(t * 1e9),
                               torque_nm=torque, force_n=force, angle_deg=angle)
                    )  # fmt: skip
                edge.on_tool_state(ToolState("pt1", run_id, 3, program, "done", at_ns + S))
            plc.publisher.put(b'{"station": "pt1", "part_id": " HEAD-3", "time_ns": 1}')
            wait_until(lambda: edge.runs.counts.bad_payloads == 1, "a bad scan counted", 10.0)
            plc.close()
    assert results() == {7: "HEAD-1", 8: "HEAD-2"}
    assert edge.runs.part_id == "HEAD-2"  # the refused scan changed nothing
