"""Station and joint configuration: TOML files, validated once at start-up.

Load with :func:`load_station` (which also loads the joint it names) or
:func:`load_joint`; pass the result down, never re-read it.
"""

from shared.config.joint import JointConfig, load_joint
from shared.config.line import derive_stations, derived_ids, load_line
from shared.config.station import (
    LoadedStation,
    PredictorSection,
    Program,
    RigSection,
    StationConfig,
    load_station,
)

__all__ = [
    "JointConfig",
    "LoadedStation",
    "PredictorSection",
    "Program",
    "RigSection",
    "StationConfig",
    "derive_stations",
    "derived_ids",
    "load_joint",
    "load_line",
    "load_station",
]
