"""The rig as the line's PLC: each part's id on zenoh before the part's first run.

The real-time rig on a python-can ``virtual`` bus, its part scanner on a real
zenoh session on loopback, heard by the tests' :class:`Listener`.
"""

from __future__ import annotations

import threading
import time
import uuid

import can
import zenoh

from services.rig.frames import RigFrames
from services.rig.part_scanner import PartScanner, starts_part
from services.rig.realtime import RealtimeRig, ToolIdentity
from shared.contract import PartScan, StationDatabase, ToolRunState, channels
from shared.runtime import ServiceSkeleton, zenoh_config
from tests.support.listener import Listener
from tests.support.live_recorder import free_port
from tests.support.rig_fixtures import constants, paper_program, quiet_rig, station

FIRST_RUN_ID = 500
RUNS = 5
SAFETY_TIMEOUT_S = 60.0


def test_which_runs_start_a_part() -> None:
    assert [starts_part(i, 2) for i in range(5)] == [True, False, True, False, True]
    assert [starts_part(i, 1) for i in range(3)] == [True, True, True]
    assert not any(starts_part(i, 0) for i in range(3))  # no parts


def test_the_rig_puts_each_part_before_its_first_run_with_the_bolts_per_part() -> None:
    """Two bolts per part, five runs: parts at runs 500, 502 and 504, each put after the run
    before it ended and before its own first ToolStatus(running)."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    channel = f"rig-{uuid.uuid4()}"
    database = StationDatabase(station().dbc_path)
    rig_section = quiet_rig(bolts_per_part=2, pause_between_runs_s=0.05)
    program = paper_program(target_force_n=12_000.0)  # from 10 kN: short runs
    statuses: list[tuple[float, int, int]] = []  # (time s, run id, state) of each ToolStatus
    with (
        zenoh.open(zenoh_config("peer", listen=[endpoint])) as line,
        Listener(line, "st1", (channels.PART.topic,)) as heard,
        ServiceSkeleton("rig") as skeleton,
        can.Bus(interface="virtual", channel=channel) as bus,
        can.Bus(interface="virtual", channel=channel) as listener,
    ):
        skeleton.own_session(zenoh.open(zenoh_config("peer", connect=[endpoint])))
        scanner = PartScanner(skeleton, "st1", rig_section)
        rig = RealtimeRig(bus, RigFrames(database), constants(), rig_section, ToolIdentity(7, True))
        stop = threading.Event()
        worker = threading.Thread(
            target=rig.run_many, args=(program, FIRST_RUN_ID, 3, stop, RUNS, scanner)
        )
        worker.start()
        try:
            deadline = time.monotonic() + SAFETY_TIMEOUT_S
            while time.monotonic() < deadline:
                message = listener.recv(timeout=0.1)
                if message is None:
                    if not worker.is_alive():
                        break  # the rig is done and the bus drained
                    continue
                if message.arbitration_id == database.tool_status_id:
                    signals = database.decode(message.arbitration_id, message.data)
                    run_id, state = int(signals["RunId"]), int(signals["State"])
                    statuses.append((message.timestamp, run_id, state))
        finally:
            stop.set()
            worker.join(SAFETY_TIMEOUT_S)
        scans: list[PartScan] = heard.wait_for(channels.PART.topic, 3)
    assert not worker.is_alive()
    assert [scan.part_id for scan in scans] == ["st1-P000500", "st1-P000502", "st1-P000504"]
    assert {scan.station for scan in scans} == {"st1"}
    assert scanner.parts == 3
    done = [run_id for _, run_id, state in statuses if state == ToolRunState.DONE]
    assert done == list(range(FIRST_RUN_ID, FIRST_RUN_ID + RUNS))
    for scan, first_run in zip(scans, (500, 502, 504), strict=True):
        started_s = min(
            t for t, run_id, s in statuses if (run_id, s) == (first_run, ToolRunState.RUNNING)
        )
        assert scan.time_ns / 1e9 < started_s, f"part of run {first_run} put after it started"
        if first_run > FIRST_RUN_ID:
            ended_s = max(
                t for t, run_id, s in statuses if (run_id, s) == (first_run - 1, ToolRunState.DONE)
            )
            assert scan.time_ns / 1e9 > ended_s, f"part of run {first_run} put during the last"
