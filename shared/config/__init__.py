"""Station and joint configuration: TOML files, validated once at start-up.

Load with :func:`load_station` (a CAN station; it also loads the joint it
names), :func:`load_any_station` (a CAN or a controller station) or
:func:`load_joint`; pass the result down, never re-read it.

- :mod:`.station` (the CAN station file), :mod:`.controller_station` (a station
  whose tool an Open Protocol controller drives), :mod:`.station_kinds` (either
  kind), :mod:`.common_sections` (what both have), :mod:`.program_windows` (a program's
  windows: where a run must end to be OK), :mod:`.final_stage` (a program's final stage
  at a lower speed, and its pulses), :mod:`.openprotocol` (a controller that
  speaks Open Protocol, and the simulated one's side), :mod:`.quality` (when the
  recorder raises a quality alert), :mod:`.retention` (how long the recorder keeps the
  recordings), :mod:`.rig_parts` (the simulated line's parts: bolts
  per part, their ids), :mod:`.joint` (the joint file),
  :mod:`.line` (a line: stations served together, stations derived from one)
- :mod:`.loading` (TOML into a validated model, errors naming file and key),
  :mod:`.toml_writer` (the files boltwatch derives from others)
"""

from shared.config.common_sections import ENDPOINT_EXPECTED, StationPlace
from shared.config.controller_station import (
    ControllerProgram,
    ControllerStation,
    ControllerStationConfig,
)
from shared.config.final_stage import FinalStage
from shared.config.joint import JointConfig, load_joint
from shared.config.line import (
    check_derivable,
    derive_stations,
    derived_ids,
    load_any_line,
    load_line,
    stations_by_id,
)
from shared.config.loading import StrictModel, read_toml, resolve_relative, validate
from shared.config.openprotocol import OpenProtocolSection, RigOpenProtocolSection
from shared.config.quality import QualitySection
from shared.config.retention import RetentionSection
from shared.config.station import (
    CanSection,
    LoadedStation,
    PredictorSection,
    Program,
    RigSection,
    StationConfig,
    ZenohSection,
    load_station,
)
from shared.config.station_kinds import AnyStation, load_any_station
from shared.config.toml_writer import dumps

__all__ = [
    "ENDPOINT_EXPECTED",
    "AnyStation",
    "CanSection",
    "ControllerProgram",
    "ControllerStation",
    "ControllerStationConfig",
    "FinalStage",
    "JointConfig",
    "LoadedStation",
    "OpenProtocolSection",
    "PredictorSection",
    "Program",
    "QualitySection",
    "RetentionSection",
    "RigOpenProtocolSection",
    "RigSection",
    "StationConfig",
    "StationPlace",
    "StrictModel",
    "ZenohSection",
    "check_derivable",
    "derive_stations",
    "derived_ids",
    "dumps",
    "load_any_line",
    "load_any_station",
    "load_joint",
    "load_line",
    "load_station",
    "read_toml",
    "resolve_relative",
    "stations_by_id",
    "validate",
]
