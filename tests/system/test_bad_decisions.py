"""Bad decision payloads against a real acquisition process: counted, one log line, no stop.

The router and ``boltwatch serve acquisition`` run as processes; the test is
the tool on the station's ``udp_multicast`` CAN bus and a hostile client on
``boltwatch/st1/decision``. While a run is running it sends decisions with an
unknown ``reason``, a string ``run_id``, times no clock can hold, a run id
wider than the DBC's ``RunId``, and payloads that are no decision at all (deep
nesting, bad JSON); none may stop the tool, each is counted in
``BusStats.bad_decisions``, the log holds one line about them and no
traceback; a good decision afterwards still stops the tool, once.
"""

from __future__ import annotations

import json
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
import zenoh

from services.cli.station_supervisor import stop_process
from shared.config import CanSection, load_station
from shared.contract import (
    StationDatabase,
    StopDecision,
    ToolRunState,
    channels,
    encode,
)
from shared.runtime import zenoh_config
from tests.support.can_injector import CanInjector, StopListener
from tests.support.listener import Listener
from tests.support.station_files import free_tcp_port, serve, write_station

pytestmark = pytest.mark.system

STATION = "st1"
RUN = 4711


@dataclass
class Station:
    can: CanSection
    database: StationDatabase
    endpoint: str
    acquisition_log: Path


@pytest.fixture
def station(tmp_path: Path) -> Iterator[Station]:
    port = free_tcp_port()
    path = write_station(tmp_path, zenoh_port=port, placement="line")  # decisions from zenoh
    config = load_station(path)
    endpoint = f"tcp/127.0.0.1:{port}"
    log = tmp_path / "acquisition.log"
    processes = [serve(["router", "--listen", endpoint], tmp_path / "router.log")]
    try:
        args = ["acquisition", "--config", str(path), "--stats-interval-s", "0.2"]
        processes.append(serve(args, log))
        yield Station(config.config.can, StationDatabase(config.dbc_path), endpoint, log)
    finally:
        for process in reversed(processes):
            stop_process(process, grace_s=10.0)


def decision_fields(run_id: int) -> dict[str, object]:
    now = time.time_ns()
    good = StopDecision(STATION, run_id, now, 0.5, "plateau_closest", "test", 1.0, None, None, now)
    fields: dict[str, object] = json.loads(encode(good))
    return fields


def bad_decisions() -> list[bytes]:
    """What a hostile client sends for the running run; the two probes a plant reported first."""
    fields = decision_fields(RUN)
    changes: list[dict[str, object]] = [
        {"reason": "stop_now_please"},
        {"run_id": str(RUN)},
        {"time_ns": -1},
        {"time_ns": 10**30},
        {"decided_ns": 2**63},
        {"time_s": float("nan")},
        {"run_id": RUN + 2**32},  # RUN on a 32-bit RunId, but no run of this bus
        {"detail": "x" * 100_000},
        {"station": "st1/../st2"},
        {"station": "st2"},  # another station's decision on this station's key
    ]
    payloads = [json.dumps({**fields, **change}).encode() for change in changes]
    return [*payloads, b"[" * 100_000 + b"]" * 100_000, b"{not json", b""]


def test_bad_decisions_are_counted_never_stop_and_a_good_one_still_does(
    station: Station,
) -> None:
    bad = bad_decisions()
    with (
        zenoh.open(zenoh_config("client", [station.endpoint])) as session,
        StopListener(station.can, station.database) as stops,
        CanInjector(station.can, station.database) as bus,
    ):
        heard = Listener(session, STATION, (channels.BUS.topic, channels.TOOL.topic))
        decisions = session.declare_publisher(
            channels.DECISION.key(STATION),
            congestion_control=zenoh.CongestionControl.BLOCK,
        )
        try:
            heard.wait(lambda: heard.of("bus"), "the acquisition's first BusStats", 20.0)
            bus.tool_status(RUN, ToolRunState.RUNNING)
            heard.wait(lambda: heard.of("tool"), "the run to start", 5.0)
            for _ in range(5):  # a flood: five of each
                for payload in bad:
                    decisions.put(payload)
            time.sleep(0.3)  # room for a wrong stop
            assert stops.heard == []  # none of them stopped the tool
            # handled after the flood (one publisher, in order): it still stops the tool
            decisions.put(json.dumps(decision_fields(RUN)).encode())
            heard_stops = stops.wait_for(1, 5.0)
            time.sleep(0.3)  # room for a wrong second stop
            assert [(s.run_id, s.reason) for s in heard_stops] == [(RUN, 1)]
            log = station.acquisition_log.read_text()
            assert "Traceback" not in log, log
            lines = [line for line in log.splitlines() if "bad decision payload" in line]
            assert len(lines) == 1, log  # rate-limited: the first at once, the next after 10 s
            heard.wait(
                lambda: heard.of("bus")[-1].stop_commands == 1,
                "BusStats after the stop",
                5.0,
            )
        finally:
            heard.close()
            decisions.undeclare()
    last = heard.of("bus")[-1]
    assert (last.bad_decisions, last.late_decisions) == (5 * len(bad), 0)
