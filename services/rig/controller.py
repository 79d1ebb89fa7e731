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

``tick()`` advances one sample period and returns that sample; the caller
sends it and asks ``finished`` whether the run is over.
"""

from __future__ import annotations

import enum
import logging

from services.rig.physics import Measurement, TighteningPhysics
from shared.config import Program
from shared.contract import ToolRunState

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
        if self.stop_source is not None:
            return False
        self._halt(StopSource.STOP_COMMAND)
        return True

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
        if self.stop_source is None:
            source = self._limit_reached(measurement) or self._shutoff_reached(measurement)
            if source is not None:
                self._halt(source)
        elif self._settled(measurement):
            self.state = ToolRunState.ABORTED if self.stop_source in LIMITS else ToolRunState.DONE
        return measurement

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
        if self.has_force_sensor and program.target_force_n is not None:
            if measurement.force_n >= program.target_force_n:
                return StopSource.SHUTOFF_FORCE
            return None
        if (
            program.target_torque_nm is not None
            and measurement.torque_nm >= program.target_torque_nm
        ):
            return StopSource.SHUTOFF_TORQUE
        return None

    def _halt(self, source: StopSource) -> None:
        self.physics.halt_motor()
        self.stop_source = source
        self.halt_time_s = self.physics.time_s
        LOG.debug("run %d: motor halted at %.3f s (%s)", self.run_id, self.halt_time_s, source)

    def _settled(self, measurement: Measurement) -> bool:
        assert self.halt_time_s is not None
        waited_s = measurement.time_s - self.halt_time_s
        return waited_s >= self._settle_time_s - 1e-9 and self.physics.settled
