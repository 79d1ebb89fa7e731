"""The simulated tool in real time: the controller paced at 1 kHz on a CAN bus.

Per run: ToolStatus(running), then every sample period a ToolSensors frame
and (with a force sensor) a JointSensors frame carrying the same 16-bit
rolling Counter (0 at the start of each run); ToolStatus every 100 ms and on
each change (done or aborted, then idle). A controller that takes StageCommand
(``[rig] stage_commands``, and a DBC that has it) sends ToolStage before the
run's first ToolStatus, on every change of its stage or pulses, and with each
ToolStatus; a StageCommand for the running run is obeyed within the tick, as
a StopCommand is. Pacing uses absolute deadlines on
``time.perf_counter``; the wait for the next deadline is ``bus.recv`` itself,
so a StopCommand for the running run halts the motor within the current tick.
More than 50 ms late: a warning, a count, and the schedule restarts from now.

Seeds: run k (0-based) of a session uses ``seed + k``, so a session is
reproducible from its seed and runs differ from each other.

Parts: with a :class:`PartSource` (the line's part scanner,
:mod:`services.rig.part_scanner`), each run that starts a part has the part
announced before the pause that precedes it; the first run (no pause
before it otherwise) waits the pause too, so a part always reaches the line
before the tool starts on it.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import can

from services.rig.controller import RunController, StopSource
from services.rig.frames import RigFrames
from services.rig.physics import TighteningPhysics
from shared.config import Program, RigSection
from shared.contract import ToolRunState, ToolStageCode
from shared.errors import TransportError
from shared.model import JointConstants

LOG = logging.getLogger(__name__)

SAMPLE_PERIOD_S = 1e-3
STATUS_PERIOD_S = 0.1
LATE_RESYNC_S = 0.05


@dataclass(frozen=True, slots=True)
class RunSummary:
    """How one run ended (what the rig logs per run)."""

    run_id: int
    program_id: int
    state: ToolRunState
    stop_source: StopSource | None
    final_force_n: float
    final_torque_nm: float
    slips: int
    samples: int
    late_resyncs: int
    pulses: int = 0


@dataclass(frozen=True, slots=True)
class ToolIdentity:
    """What the rig is on the bus."""

    tool_id: int
    has_force_sensor: bool


class PartSource(Protocol):
    """Who announces the part a run tightens (the line's PLC or scanner)."""

    def before_run(self, index: int, run_id: int) -> bool:
        """Before run ``index`` (from 0) and its pause: True when the run starts a
        new part (announced now)."""


class RealtimeRig:
    """Runs tightenings one after another on ``bus`` (which the caller owns and closes)."""

    def __init__(
        self,
        bus: can.BusABC,
        frames: RigFrames,
        constants: JointConstants,
        rig: RigSection,
        tool: ToolIdentity,
        clock: Callable[[], float] = time.perf_counter,
    ) -> None:
        self._bus = bus
        self._frames = frames
        self._constants = constants
        self._rig = rig
        self._tool = tool
        self._clock = clock
        self.late_resyncs_total = 0

    def run_many(
        self,
        program: Program,
        first_run_id: int,
        seed: int,
        stop: threading.Event,
        runs: int | None = None,
        parts: PartSource | None = None,
    ) -> list[RunSummary]:
        """``runs`` runs (None: until ``stop``), pausing ``pause_between_runs_s`` between;
        ``parts``: told before each run (and its pause), announces each new part."""
        summaries: list[RunSummary] = []
        index = 0
        while not stop.is_set() and (runs is None or index < runs):
            new_part = parts is not None and parts.before_run(index, first_run_id + index)
            if index > 0:
                self._idle(self._rig.pause_between_runs_s, summaries[-1].run_id, program, stop)
            elif new_part:  # the tool says nothing yet: it waits for the part to be known
                stop.wait(self._rig.pause_between_runs_s)
            if stop.is_set():
                break
            summary = self.run_one(program, first_run_id + index, seed + index, stop)
            summaries.append(summary)
            LOG.info(
                "run %d: %s by %s, force %.0f N, torque %.1f Nm, %d slips, %d samples, %d late, "
                "%d pulses",
                summary.run_id,
                summary.state.name.lower(),
                summary.stop_source,
                summary.final_force_n,
                summary.final_torque_nm,
                summary.slips,
                summary.samples,
                summary.late_resyncs,
                summary.pulses,
            )
            index += 1
        return summaries

    def run_one(
        self, program: Program, run_id: int, seed: int, stop: threading.Event
    ) -> RunSummary:
        """One tightening in real time; returns after the final ToolStatus(idle)."""
        physics = TighteningPhysics(self._constants, program, self._rig, seed, SAMPLE_PERIOD_S)
        stages = self._rig.stage_commands and self._frames.has_stages
        controller = RunController(
            physics,
            program,
            run_id,
            settle_time_s=self._rig.settle_time_s,
            has_force_sensor=self._tool.has_force_sensor,
            accepts_stages=stages,
        )
        reported: tuple[ToolStageCode, int] | None = None
        if stages:  # what it takes, before the run starts (the station fixes it per run)
            reported = self._send_stage(controller)
        controller.start()
        self._send_status(controller)
        late = 0
        counter = 0
        start = self._clock()
        deadline = start
        next_status = start + STATUS_PERIOD_S
        while True:
            measurement = controller.tick()
            if stages and reported != (controller.stage, controller.pulses):
                reported = self._send_stage(controller)
            self._send(
                self._frames.tool_sensors(measurement.torque_nm, measurement.angle_deg, counter)
            )
            if self._tool.has_force_sensor:
                self._send(self._frames.joint_sensors(measurement.force_n, counter))
            counter += 1
            if controller.finished:
                break
            if stop.is_set():
                controller.interrupt()
                break
            now = self._clock()
            if now >= next_status:
                self._send_status(controller)
                if stages:
                    reported = self._send_stage(controller)
                next_status = now + STATUS_PERIOD_S
            deadline += SAMPLE_PERIOD_S
            lateness_s = now - deadline
            if lateness_s > LATE_RESYNC_S:
                late += 1
                LOG.warning("run %d: %.0f ms behind schedule, resyncing", run_id, lateness_s * 1e3)
                deadline = now
            self._wait_until(deadline, controller)
        self._send_status(controller)
        self._send(
            self._frames.tool_status(run_id, self._tool.tool_id, program.id, ToolRunState.IDLE)
        )
        self.late_resyncs_total += late
        return RunSummary(
            run_id=run_id,
            program_id=program.id,
            state=ToolRunState(controller.state),
            stop_source=controller.stop_source,
            final_force_n=physics.true_force_n,
            final_torque_nm=physics.true_torque_nm,
            slips=physics.slip_count,
            samples=controller.samples,
            late_resyncs=late,
            pulses=controller.pulses,
        )

    def _wait_until(self, deadline: float, controller: RunController) -> None:
        """Receive until ``deadline``; a StopCommand for this run halts the motor at once."""
        while True:
            remaining_s = deadline - self._clock()
            message = self._bus.recv(timeout=max(0.0, remaining_s))
            if message is not None:
                run_id = self._frames.stop_command_run_id(message)
                if run_id is not None and controller.request_stop(run_id):
                    LOG.info("run %d: StopCommand obeyed", run_id)
                stage = self._frames.stage_command(message)
                if stage is not None and controller.request_stage(*stage):
                    LOG.info("run %d: StageCommand %s obeyed", stage[0], stage[1].name.lower())
            if self._clock() >= deadline:
                return

    def _idle(
        self, pause_s: float, last_run_id: int, program: Program, stop: threading.Event
    ) -> None:
        """Between runs: ToolStatus(idle) every 100 ms, StopCommands ignored."""
        end = self._clock() + pause_s
        while not stop.is_set():
            now = self._clock()
            if now >= end:
                return
            self._send(
                self._frames.tool_status(
                    last_run_id, self._tool.tool_id, program.id, ToolRunState.IDLE
                )
            )
            wait_end = min(end, now + STATUS_PERIOD_S)
            while not stop.is_set() and self._clock() < wait_end:
                self._bus.recv(timeout=min(0.01, max(0.0, wait_end - self._clock())))

    def _send_stage(self, controller: RunController) -> tuple[ToolStageCode, int]:
        """ToolStage now; the (stage, pulses) it reported."""
        stage = controller.final_stage
        self._send(
            self._frames.tool_stage(
                controller.run_id,
                controller.stage,
                controller.pulses,
                stage.max_pulses if stage is not None else 0,
            )
        )
        return controller.stage, controller.pulses

    def _send_status(self, controller: RunController) -> None:
        self._send(
            self._frames.tool_status(
                controller.run_id, self._tool.tool_id, controller.program.id, controller.state
            )
        )

    def _send(self, message: can.Message) -> None:
        try:
            self._bus.send(message)
        except can.CanError as err:
            raise TransportError(f"CAN send failed: {err}") from err
