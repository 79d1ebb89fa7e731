"""One station a predictor process serves: its own programs, sensors, joint and settings.

A line predictor serves several stations; each run is predicted with the
configuration of the station it belongs to, never another's.
"""

from __future__ import annotations

from services.predictor.core import PredictorSettings
from shared.config import LoadedStation, Program
from shared.model import JointConstants


class ServedStation:
    """A loaded station file plus what the predictor derives from it once."""

    def __init__(self, station: LoadedStation) -> None:
        self.station = station
        self.station_id = station.station_id
        self._constants: dict[int, JointConstants] = {}  # by program: its joint's

    def program(self, program_id: int) -> Program:
        """The station's program; KeyError names the station and its known ids."""
        return self.station.config.program(program_id)

    def settings(self, program: Program) -> PredictorSettings:
        """The core's settings for one run of ``program`` at this station."""
        config = self.station.config
        constants = self._constants.get(program.id)
        if constants is None:
            constants = JointConstants.of(self.station.joint_of(program.id))
            self._constants[program.id] = constants
        return PredictorSettings.of(
            program,
            config.predictor,
            config.station.has_force_sensor,
            constants,
            self.station.sensor_range,
        )
