"""The real-time rig on an in-process python-can ``virtual`` bus (no mocks)."""

from __future__ import annotations

import threading
import time
import uuid
from collections.abc import Iterator
from contextlib import contextmanager

import can

from services.rig.controller import StopSource
from services.rig.frames import RigFrames
from services.rig.realtime import RealtimeRig, RunSummary, ToolIdentity
from shared.config import Program
from shared.contract import StationDatabase, ToolRunState
from tests.support.rig_fixtures import constants, paper_program, paper_rig, station

TOOL_ID = 7
RUN_ID = 1_700_000_000
SAFETY_TIMEOUT_S = 20.0


def database() -> StationDatabase:
    return StationDatabase(station().dbc_path)


@contextmanager
def rig_in_thread(
    program: Program, channel: str, has_force_sensor: bool = True
) -> Iterator[list[RunSummary]]:
    """Run one run of the rig in a thread on ``channel``; yields its summaries when done."""
    summaries: list[RunSummary] = []
    stop = threading.Event()
    rig_section = paper_rig().model_copy(update={"pause_between_runs_s": 0.0})
    with can.Bus(interface="virtual", channel=channel) as bus:
        rig = RealtimeRig(
            bus,
            RigFrames(database()),
            constants(),
            rig_section,
            ToolIdentity(TOOL_ID, has_force_sensor),
        )
        worker = threading.Thread(
            target=lambda: summaries.extend(rig.run_many(program, RUN_ID, 3, stop, runs=1))
        )
        worker.start()
        try:
            yield summaries
        except BaseException:
            stop.set()
            raise
        finally:
            worker.join(SAFETY_TIMEOUT_S)
            stop.set()
            worker.join(SAFETY_TIMEOUT_S)
    assert not worker.is_alive()


def frames_until_idle(
    bus: can.BusABC, db: StationDatabase, stop_after_samples: int | None = None
) -> list[tuple[str, dict[str, float | int]]]:
    """Decoded frames until ToolStatus(idle); optionally sends a StopCommand midway."""
    frames: list[tuple[str, dict[str, float | int]]] = []
    tool_samples = 0
    give_up = time.monotonic() + SAFETY_TIMEOUT_S
    while time.monotonic() < give_up:
        message = bus.recv(timeout=0.5)
        if message is None or message.arbitration_id not in db.by_id:
            continue
        name, _ = db.by_id[message.arbitration_id]
        signals = db.decode(message.arbitration_id, message.data)
        frames.append((name, signals))
        if name == "ToolSensors":
            tool_samples += 1
            if tool_samples == stop_after_samples:
                for run_id in (RUN_ID + 1, RUN_ID):  # another run's stop is ignored
                    data = db.encode("StopCommand", {"RunId": run_id, "Reason": 1})
                    bus.send(
                        can.Message(
                            arbitration_id=db.stop_command_id, data=data, is_extended_id=False
                        )
                    )
        if name == "ToolStatus" and signals["State"] == ToolRunState.IDLE:
            return frames
    raise AssertionError("no ToolStatus(idle) from the rig")


def test_one_run_sends_paired_samples_and_statuses() -> None:
    channel = f"rig-{uuid.uuid4()}"
    db = database()
    with (
        can.Bus(interface="virtual", channel=channel) as listener,
        rig_in_thread(paper_program(target_force_n=14_000.0), channel) as summaries,
    ):
        frames = frames_until_idle(listener, db)
    tool = [s for name, s in frames if name == "ToolSensors"]
    joint = [s for name, s in frames if name == "JointSensors"]
    statuses = [s for name, s in frames if name == "ToolStatus"]
    assert [s["Counter"] for s in tool] == list(range(len(tool)))
    assert [s["Counter"] for s in joint] == [s["Counter"] for s in tool]
    states = [s["State"] for s in statuses]
    assert states[0] == ToolRunState.RUNNING
    assert states[-2:] == [ToolRunState.DONE, ToolRunState.IDLE]
    assert set(states[:-2]) == {ToolRunState.RUNNING}
    assert len(statuses) >= 3  # 10 Hz while running (a run of > 100 ms)
    assert {s["RunId"] for s in statuses} == {RUN_ID}
    assert {s["ToolId"] for s in statuses} == {TOOL_ID}
    (summary,) = summaries
    assert summary.stop_source is StopSource.SHUTOFF_FORCE
    assert summary.samples == len(tool)
    assert max(float(s["Force"]) for s in joint) >= 14_000.0


def test_stop_command_ends_the_run_early() -> None:
    channel = f"rig-{uuid.uuid4()}"
    db = database()
    with (
        can.Bus(interface="virtual", channel=channel) as listener,
        rig_in_thread(paper_program(target_force_n=50_000.0), channel) as summaries,
    ):
        frames = frames_until_idle(listener, db, stop_after_samples=20)
    (summary,) = summaries
    assert summary.stop_source is StopSource.STOP_COMMAND
    assert summary.state is ToolRunState.DONE
    assert summary.final_force_n < 20_000.0
    assert [s["State"] for n, s in frames if n == "ToolStatus"][-2] == ToolRunState.DONE


def test_torque_only_station_sends_no_joint_sensors() -> None:
    channel = f"rig-{uuid.uuid4()}"
    db = database()
    program = paper_program(target_torque_nm=60.0)
    with (
        can.Bus(interface="virtual", channel=channel) as listener,
        rig_in_thread(program, channel, has_force_sensor=False) as summaries,
    ):
        frames = frames_until_idle(listener, db)
    assert not [name for name, _ in frames if name == "JointSensors"]
    assert summaries[0].stop_source is StopSource.SHUTOFF_TORQUE
