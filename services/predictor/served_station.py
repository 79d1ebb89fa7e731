"""One station a predictor process serves: its own programs, sensors, joint and settings.

A line predictor serves several stations; each run is predicted with the
configuration of the station it belongs to, never another's. Its samples and
tool states are decoded with ids only as wide as the station's DBC carries
them (``RunId``, ``ToolId``, ``ProgramId`` of ``ToolStatus``): they come from
its CAN bus, and a wider one is no run of this station. Its part scans come
from the line (``boltwatch/<st>/part``), decoded with the contract's bounds.
"""

from __future__ import annotations

from collections.abc import Callable

from shared.config import LoadedStation, Program
from shared.contract import (
    PartScan,
    Sample,
    StationDatabase,
    ToolCommandsName,
    ToolState,
    can_id_bounds,
    codec,
)
from shared.model import JointConstants
from shared.stickslip import PredictorSettings


class ServedStation:
    """A loaded station file plus what the predictor derives from it once."""

    def __init__(self, station: LoadedStation) -> None:
        self.station = station
        self.station_id = station.station_id
        self._constants: dict[int, JointConstants] = {}  # by program: its joint's
        ids = can_id_bounds(StationDatabase(station.dbc_path))
        self.decode_sample: Callable[[bytes], Sample] = codec.decoder(
            Sample, {"run_id": ids["run_id"]}
        )
        self.decode_tool_state: Callable[[bytes], ToolState] = codec.decoder(ToolState, ids)
        self.decode_part: Callable[[bytes], PartScan] = codec.decoder(PartScan)

    def program(self, program_id: int) -> Program:
        """The station's program; KeyError names the station and its known ids."""
        return self.station.config.program(program_id)

    def settings(self, program: Program, commands: ToolCommandsName = "stop") -> PredictorSettings:
        """The core's settings for one run of ``program`` at this station (``commands``:
        what its tool takes for this run; "staged" runs the program's final stage)."""
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
            commands,
        )
