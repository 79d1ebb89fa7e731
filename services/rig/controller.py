"""The tool controller of one run on top of the physics. Pure: no clock, no CAN.

What every tool controller does by itself, boltwatch or not:

* conventional shutoff: stop the motor when the measured force first reaches
  ``target_force_n``; on a program without a force target, or a station
  without a force sensor, when the measured torque reaches ``target_torque_nm``
  (a dead predictor therefore means a conventional stop);
* hard limits (``max_torque_nm``, ``max_force_n``, ``max_angle_deg``,
  ``max_time_s``): stop and end the run ABORTED;
* a StopCommand for the running run: stop now, end DONE;
* after the motor stops, keep sampling for ``settle_time_s`` (and until a slip
  under way has finished), then end.

A program with a final stage, on a controller that takes stage commands
(``accepts_stages``; the CAN side: ``docs/reference/can-and-trace.md``):

* rundown at the program's speed; the final stage's speed on a
  ``StageCommand`` final (back to the rundown speed on one saying rundown),
  or by itself at ``switch_torque_nm`` (``switch = "torque"``);
* a halt (a StopCommand, its own shutoff) leaves the run HOLDING, open for a
  pulse (the final speed again, until the next halt; at most ``max_pulses``)
  or a finish (the run ends DONE); after ``hold_s`` without either, and once
  a slip under way has finished, it ends the run by itself: a station that
  went quiet never holds the tool;
* its own shutoff at the target watches the torque (the preload) averaged
  over :data:`FINAL_SHUTOFF_SAMPLES` samples in the final stage and a pulse,
  as a controller filters its transducer on a slow final step (one noisy
  sample would halt it short of the target).

``tick()`` advances one sample period and returns that sample; the caller
sends it and asks ``finished`` whether the run is over.
"""

from __future__ import annotations

import enum
import logging
import statistics
from collections import deque

from services.rig.physics import Measurement, TighteningPhysics
from shared.config import Program
from shared.contract import StageCommandCode, ToolRunState, ToolStageCode

LOG = logging.getLogger(__name__)


class StopSource(enum.StrEnum):
    """Why the motor stopped."""

    STOP_COMMAND = "stop_command"
    SHUTOFF_FORCE = "shutoff_force"
    SHUTOFF_TORQUE = "shutoff_torque"
    LIMIT_TORQUE = "limit_torque"
    LIMIT_FORCE = "limit_force"
    LIMIT_ANGLE = "limit_angle"
    LIMIT_TIME = "limit_time"
    SERVICE_STOP = "service_stop"


#: samples of the torque its own shutoff averages in the final stage and a pulse
FINAL_SHUTOFF_SAMPLES = 8

LIMITS = frozenset(
    {StopSource.LIMIT_TORQUE, StopSource.LIMIT_FORCE, StopSource.LIMIT_ANGLE, StopSource.LIMIT_TIME}
)


class RunController:
    """One run of the tool: IDLE -> RUNNING -> DONE | ABORTED (the ToolStatus states)."""

    def __init__(
        self,
        physics: TighteningPhysics,
        program: Program,
        run_id: int,
        *,
        settle_time_s: float,
        has_force_sensor: bool = True,
        shutoff: bool = True,
        accepts_stages: bool = True,
    ) -> None:
        self.physics = physics
        self.program = program
        self.run_id = run_id
        self.has_force_sensor = has_force_sensor
        self._settle_time_s = settle_time_s
        self._shutoff = shutoff
        self.state = ToolRunState.IDLE
        self.stop_source: StopSource | None = None
        self.halt_time_s: float | None = None
        self.samples = 0
        self.last: Measurement | None = None
        #: the program's final stage, when this controller runs it (None: stop only)
        self.final_stage = program.final_stage if accepts_stages else None
        self.accepts_stages = accepts_stages
        self.stage = ToolStageCode.RUNDOWN
        self.pulses = 0
        self._held_since_s: float | None = None  # HOLDING since (run seconds)
        self._finish_asked = False
        self._recent_torque: deque[float] = deque(maxlen=FINAL_SHUTOFF_SAMPLES)
        self._recent_force: deque[float] = deque(maxlen=FINAL_SHUTOFF_SAMPLES)

    @property
    def staged(self) -> bool:
        """This run runs a final stage (the program has one and the controller takes it)."""
        return self.final_stage is not None

    @property
    def finished(self) -> bool:
        return self.state in (ToolRunState.DONE, ToolRunState.ABORTED)

    def start(self) -> None:
        if self.state is not ToolRunState.IDLE:
            raise RuntimeError(f"run {self.run_id} already started ({self.state.name})")
        self.state = ToolRunState.RUNNING

    def request_stop(self, run_id: int) -> bool:
        """A StopCommand: obeyed (True) only for this run while its motor turns."""
        if run_id != self.run_id or self.state is not ToolRunState.RUNNING:
            return False
        if not self.physics.motor_running or self.stage is ToolStageCode.HOLDING:
            return False
        if self.stop_source is not None and self.stage is not ToolStageCode.PULSE:
            return False
        self._halt(StopSource.STOP_COMMAND)
        return True

    def request_stage(self, run_id: int, command: StageCommandCode) -> bool:
        """A StageCommand: obeyed (True) only for this run, by a staged run, in a stage where
        it applies (final, rundown: while the motor turns in the rundown or final stage;
        pulse, finish: while holding; a pulse while pulses are left)."""
        stage = self.final_stage
        if stage is None or run_id != self.run_id or self.state is not ToolRunState.RUNNING:
            return False
        if command is StageCommandCode.FINAL and self.stage is ToolStageCode.RUNDOWN:
            self._run_at(ToolStageCode.FINAL, stage.speed_rad_s)
        elif command is StageCommandCode.RUNDOWN and self.stage is ToolStageCode.FINAL:
            self._run_at(ToolStageCode.RUNDOWN, self.program.motor_speed_rad_s)
        elif (
            command is StageCommandCode.PULSE
            and self.stage is ToolStageCode.HOLDING
            and self.pulses < stage.max_pulses
            and self.stop_source not in LIMITS
        ):
            self.pulses += 1
            self._held_since_s = None
            self._run_at(ToolStageCode.PULSE, stage.speed_rad_s)
        elif command is StageCommandCode.FINISH and self.stage is ToolStageCode.HOLDING:
            self._finish_asked = True
        else:
            return False
        return True

    def _run_at(self, stage: ToolStageCode, speed_rad_s: float) -> None:
        self.stage = stage
        self._recent_torque.clear()
        self._recent_force.clear()
        self.physics.set_motor_speed(speed_rad_s)
        LOG.debug("run %d: %s at %.4g rad/s", self.run_id, stage.name.lower(), speed_rad_s)

    def interrupt(self) -> None:
        """The service is shutting down: halt now and end the run ABORTED."""
        if self.state is not ToolRunState.RUNNING:
            return
        if self.stop_source is None:
            self._halt(StopSource.SERVICE_STOP)
        self.state = ToolRunState.ABORTED

    def tick(self) -> Measurement:
        """One sample period: advance the physics, apply shutoff and limits."""
        if self.state is not ToolRunState.RUNNING:
            raise RuntimeError(f"run {self.run_id} is not running ({self.state.name})")
        measurement = self.physics.advance()
        self.samples += 1
        self.last = measurement
        self._recent_torque.append(measurement.torque_nm)
        self._recent_force.append(measurement.force_n)
        if self.physics.motor_running:
            source = self._limit_reached(measurement) or self._shutoff_reached(measurement)
            if source is not None:
                self._halt(source)
            else:
                self._switch_by_torque(measurement)
        elif self._ended(measurement):
            self.state = ToolRunState.ABORTED if self.stop_source in LIMITS else ToolRunState.DONE
        return measurement

    def _switch_by_torque(self, measurement: Measurement) -> None:
        """``switch = "torque"``: the final stage at the controller's own switch point."""
        stage = self.final_stage
        if (
            stage is not None
            and stage.switch == "torque"
            and self.stage is ToolStageCode.RUNDOWN
            and stage.switch_torque_nm is not None
            and measurement.torque_nm >= stage.switch_torque_nm
        ):
            self._run_at(ToolStageCode.FINAL, stage.speed_rad_s)

    def _limit_reached(self, measurement: Measurement) -> StopSource | None:
        program = self.program
        if measurement.torque_nm >= program.max_torque_nm:
            return StopSource.LIMIT_TORQUE
        if (
            self.has_force_sensor
            and program.max_force_n is not None
            and measurement.force_n >= program.max_force_n
        ):
            return StopSource.LIMIT_FORCE
        if measurement.angle_deg >= program.max_angle_deg:
            return StopSource.LIMIT_ANGLE
        if measurement.time_s >= program.max_time_s:
            return StopSource.LIMIT_TIME
        return None

    def _shutoff_reached(self, measurement: Measurement) -> StopSource | None:
        if not self._shutoff:
            return None
        program = self.program
        torque_nm, force_n = measurement.torque_nm, measurement.force_n
        if self.stage in (ToolStageCode.FINAL, ToolStageCode.PULSE):
            # a slow step: the filtered values (module docstring)
            torque_nm = statistics.fmean(self._recent_torque)
            force_n = statistics.fmean(self._recent_force)
        if self.has_force_sensor and program.target_force_n is not None:
            if force_n >= program.target_force_n:
                return StopSource.SHUTOFF_FORCE
            return None
        if program.target_torque_nm is not None and torque_nm >= program.target_torque_nm:
            return StopSource.SHUTOFF_TORQUE
        return None

    def _halt(self, source: StopSource) -> None:
        self.physics.halt_motor()
        if self.stop_source is None or source in LIMITS:  # the run's first halt, or a limit
            self.stop_source = source
        self.halt_time_s = self.physics.time_s
        if self.staged:
            self.stage = ToolStageCode.HOLDING
            self._held_since_s = self.halt_time_s
        LOG.debug("run %d: motor halted at %.3f s (%s)", self.run_id, self.halt_time_s, source)

    def _ended(self, measurement: Measurement) -> bool:
        """The motor stands: is the run over? (its settle time, or a staged run's hold)"""
        if not self.physics.settled:
            return False
        if self.staged and self.stop_source not in LIMITS:
            if self._finish_asked:
                return True
            assert self.final_stage is not None and self._held_since_s is not None
            held_s = measurement.time_s - self._held_since_s
            return held_s >= self.final_stage.hold_s - 1e-9
        assert self.halt_time_s is not None
        waited_s = measurement.time_s - self.halt_time_s
        return waited_s >= self._settle_time_s - 1e-9
