"""A simulated multi-spindle system: N spindles tightening one part in one synchronised cycle.

One bus, N spindles, each a tool controller of its own on the paper's physics
(:class:`~services.rig.controller.RunController`): its own joint (its own
seed: each stick phase draws its friction from the joint's scatter,
``[rig] mu_stick_scatter``), its own tool id (``[station] spindle_tool_ids``),
its own run id, its frames at the DBC's ids shifted by its stride
(:class:`~shared.contract.SpindleIds`) with its own ``Counter``, and it obeys
the ``StopCommand`` (and ``StageCommand``) at its own id.

A cycle: ``CycleStart`` (its sync id: the run id of its spindle 1), then each
spindle's ``ToolStatus`` running; every sample period each running spindle's
``ToolSensors`` and ``JointSensors``; ``ToolStatus`` (and ``CycleStart``)
every 100 ms. A spindle whose run ends sends its ``ToolStatus`` done (or
aborted) at once and then idles until the last spindle has ended, as a real
sync waits at its sync point: the next cycle starts, after the pause, with
every spindle. Cycle c (from 0) runs run ids ``first + c * N .. + N - 1``
with seeds ``seed + c * N + (k - 1)``. A part per cycle (when the rig
announces parts): a multi-spindle system tightens one part's bolts in one
cycle.
"""

from __future__ import annotations

import logging
import threading
from dataclasses import dataclass

import can

from services.rig.controller import RunController
from services.rig.frames import RigFrames
from services.rig.physics import TighteningPhysics
from services.rig.realtime import (
    LATE_RESYNC_S,
    SAMPLE_PERIOD_S,
    STATUS_PERIOD_S,
    PartSource,
    RealtimeRig,
    RunSummary,
)
from shared.config import Program
from shared.contract import ToolRunState, ToolStageCode

LOG = logging.getLogger(__name__)


@dataclass(slots=True)
class _Spindle:
    """One spindle's run in the cycle under way."""

    number: int
    tool_id: int
    frames: RigFrames
    controller: RunController
    physics: TighteningPhysics
    stages: bool  # its controller takes StageCommand (and sends ToolStage)
    counter: int = 0
    reported_end: bool = False  # its end (done, aborted) sent
    reported: tuple[ToolStageCode, int] | None = None  # the last ToolStage's (stage, pulses)


class MultiSpindleRig(RealtimeRig):
    """Synchronised cycles of N spindles on one bus (``run_many`` counts cycles)."""

    def __init__(
        self,
        *args: object,
        tool_ids: list[int],
        id_stride: int,
        **kwargs: object,
    ) -> None:
        super().__init__(*args, **kwargs)  # type: ignore[arg-type]
        self._tool_ids = tool_ids
        self._spindle_frames = [
            RigFrames(self._frames.database, (k - 1) * id_stride)
            for k in range(1, len(tool_ids) + 1)
        ]

    @property
    def spindles(self) -> int:
        return len(self._tool_ids)

    def run_many(
        self,
        program: Program,
        first_run_id: int,
        seed: int,
        stop: threading.Event,
        runs: int | None = None,
        parts: PartSource | None = None,
    ) -> list[RunSummary]:
        """``runs`` cycles (None: until ``stop``) of every spindle; each spindle's summary."""
        summaries: list[RunSummary] = []
        spindles = self.spindles
        cycle = 0
        while not stop.is_set() and (runs is None or cycle < runs):
            first = first_run_id + cycle * spindles
            new_part = parts is not None and parts.before_run(cycle, first)
            if cycle > 0 or new_part:
                stop.wait(self._rig.pause_between_runs_s)
            if stop.is_set():
                break
            ended = self.run_cycle(program, first, seed + cycle * spindles, stop)
            summaries.extend(ended)
            LOG.info(
                "cycle %d (runs %d to %d): %s",
                first,
                first,
                first + spindles - 1,
                ", ".join(
                    f"{s.state.name.lower()} {s.final_force_n:.0f} N by {s.stop_source}"
                    for s in ended
                ),
            )
            cycle += 1
        return summaries

    def run_cycle(
        self, program: Program, first_run_id: int, seed: int, stop: threading.Event
    ) -> list[RunSummary]:
        """One synchronised cycle in real time: spindle k runs ``first_run_id + k - 1``; returns
        when the last spindle's run has ended (each spindle's summary, in spindle order)."""
        sync_id = first_run_id
        spindles = self._start_cycle(program, first_run_id, seed)
        late = 0
        deadline = self._clock()
        next_status = deadline + STATUS_PERIOD_S
        running = list(spindles)
        while running:
            for spindle in running:
                self._tick(spindle)
            if stop.is_set():
                for spindle in running:
                    spindle.controller.interrupt()
            for spindle in running:
                if spindle.controller.finished:  # its end at once; it waits for the others
                    self._send_spindle_status(spindle)
                    spindle.reported_end = True
            running = [s for s in running if not s.reported_end]
            if not running:
                break
            now = self._clock()
            if now >= next_status:
                self._status_round(sync_id, spindles)
                next_status = now + STATUS_PERIOD_S
            deadline += SAMPLE_PERIOD_S
            lateness_s = now - deadline
            if lateness_s > LATE_RESYNC_S:
                late += 1
                LOG.warning(
                    "cycle %d: %.0f ms behind schedule, resyncing", sync_id, lateness_s * 1e3
                )
                deadline = now
            self._wait_for_spindles(deadline, running)
        for spindle in spindles:  # the cycle is over: every spindle idle
            self._send(
                spindle.frames.tool_status(
                    spindle.controller.run_id, spindle.tool_id, program.id, ToolRunState.IDLE
                )
            )
        self.late_resyncs_total += late
        return [_summary(spindle, late) for spindle in spindles]

    def _start_cycle(self, program: Program, first_run_id: int, seed: int) -> list[_Spindle]:
        """Every spindle's run, started: CycleStart, then each spindle's ToolStage (a staged
        controller) and ToolStatus running."""
        stages = self._rig.stage_commands and self._frames.has_stages
        spindles = []
        for index, (frames, tool_id) in enumerate(
            zip(self._spindle_frames, self._tool_ids, strict=True)
        ):
            physics = TighteningPhysics(
                self._constants, program, self._rig, seed + index, SAMPLE_PERIOD_S
            )
            controller = RunController(
                physics,
                program,
                first_run_id + index,
                settle_time_s=self._rig.settle_time_s,
                has_force_sensor=self._tool.has_force_sensor,
                accepts_stages=stages,
            )
            spindles.append(_Spindle(index + 1, tool_id, frames, controller, physics, stages))
        self._send(self._frames.cycle_start(first_run_id, len(spindles)))
        for spindle in spindles:
            if stages:
                self._send_spindle_stage(spindle)
            spindle.controller.start()
            self._send_spindle_status(spindle)
        return spindles

    def _tick(self, spindle: _Spindle) -> None:
        """One sample period of a running spindle: its physics, then its frames."""
        controller = spindle.controller
        measurement = controller.tick()
        if spindle.stages and spindle.reported != (controller.stage, controller.pulses):
            self._send_spindle_stage(spindle)
        frames, counter = spindle.frames, spindle.counter
        self._send(frames.tool_sensors(measurement.torque_nm, measurement.angle_deg, counter))
        if self._tool.has_force_sensor:
            self._send(frames.joint_sensors(measurement.force_n, counter))
        spindle.counter = counter + 1

    def _status_round(self, sync_id: int, spindles: list[_Spindle]) -> None:
        """Every 100 ms: CycleStart again, and each spindle's ToolStatus (and ToolStage)."""
        self._send(self._frames.cycle_start(sync_id, len(spindles)))
        for spindle in spindles:
            self._send_spindle_status(spindle)
            if spindle.stages and not spindle.reported_end:
                self._send_spindle_stage(spindle)

    def _wait_for_spindles(self, deadline: float, running: list[_Spindle]) -> None:
        """Receive until ``deadline``; a StopCommand (StageCommand) at a spindle's id for its
        run is obeyed at once."""
        while True:
            remaining_s = deadline - self._clock()
            message = self._bus.recv(timeout=max(0.0, remaining_s))
            if message is not None:
                self._obey(message, running)
            if self._clock() >= deadline:
                return

    def _obey(self, message: can.Message, running: list[_Spindle]) -> None:
        for spindle in running:
            frames, controller = spindle.frames, spindle.controller
            run_id = frames.stop_command_run_id(message)
            if run_id is not None:
                if controller.request_stop(run_id):
                    LOG.info("run %d (spindle %d): StopCommand obeyed", run_id, spindle.number)
                return
            stage = frames.stage_command(message)
            if stage is not None:
                if controller.request_stage(*stage):
                    LOG.info(
                        "run %d (spindle %d): StageCommand %s obeyed",
                        stage[0],
                        spindle.number,
                        stage[1].name.lower(),
                    )
                return

    def _send_spindle_status(self, spindle: _Spindle) -> None:
        controller = spindle.controller
        self._send(
            spindle.frames.tool_status(
                controller.run_id, spindle.tool_id, controller.program.id, controller.state
            )
        )

    def _send_spindle_stage(self, spindle: _Spindle) -> None:
        controller = spindle.controller
        stage = controller.final_stage
        self._send(
            spindle.frames.tool_stage(
                controller.run_id,
                controller.stage,
                controller.pulses,
                stage.max_pulses if stage is not None else 0,
            )
        )
        spindle.reported = (controller.stage, controller.pulses)


def _summary(spindle: _Spindle, late: int) -> RunSummary:
    controller, physics = spindle.controller, spindle.physics
    return RunSummary(
        run_id=controller.run_id,
        program_id=controller.program.id,
        state=ToolRunState(controller.state),
        stop_source=controller.stop_source,
        final_force_n=physics.true_force_n,
        final_torque_nm=physics.true_torque_nm,
        slips=physics.slip_count,
        samples=controller.samples,
        late_resyncs=late,
        pulses=controller.pulses,
    )
