"""A station file of either kind, for what serves every station: the bridge, recorder, tools.

Two kinds of station file (docs/reference/configuration.md):

- a CAN station (:class:`~shared.config.station.LoadedStation`): ``[can]``, a
  joint, programs with motor speed and hard limits; its tool is read over
  CAN (or simulated by the rig, also as an Open Protocol controller);
- a controller station (:class:`~shared.config.controller_station.ControllerStation`):
  ``[openprotocol]`` without ``[can]``; its tool is a controller's, bridged.

Both have ``path``, ``config`` (``station``, ``zenoh``, ``recorder``,
``quality``, ``openprotocol``, ``programs``, ``program(id)``), ``station_id``,
``sensor_range``, ``recordings_folder`` and ``make_recordings_folder()``;
what only one kind has (a joint, a DBC, a pset's lack of limits) is reached
after an ``isinstance``. The rig, the acquisition, the predictor, ``simulate``
and ``predict`` load with :func:`shared.config.station.load_station` (CAN
only, a clear refusal of a controller station); the bridge, the recorder,
``status``, ``health``, the dashboard, ``inspect``, ``report`` and ``wear``
with :func:`load_any_station`.
"""

from __future__ import annotations

from pathlib import Path

from shared.config.controller_station import (
    ControllerStation,
    is_controller_station,
    load_controller_station,
)
from shared.config.loading import read_toml
from shared.config.station import LoadedStation, can_station

#: a loaded station file of either kind
AnyStation = LoadedStation | ControllerStation


def load_any_station(path: Path) -> AnyStation:
    """The station of ``path``, of the kind its file is; every error names file and key."""
    path = Path(path)
    data = read_toml(path)
    if is_controller_station(data):
        return load_controller_station(path, data)
    return can_station(path, data)
