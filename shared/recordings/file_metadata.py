"""The MCAP metadata records of a recording: who recorded what, with which settings.

Each file carries (MCAP metadata records, string to string):

``station``   station id, tool id, station file, recorder software version
``run``       run id, tool id and program id as the tool reported them (run files)
``program``   the program's parameters from the station file (run files; a
              controller station's pset: its id, name and windows)
``joint``     the joint parameters (JointConfig, nested keys dotted; a CAN
              station's only: a controller station models no joint)

One recorder serves several stations (``serve recorder --config A B ...``):
each station's records come from its own station file. A station with no
file here (its messages are still recorded) gets ``station`` and ``run``
only, and a warning once. ``extra`` records (e.g. ``controller`` of an
imported controller run) are added to every file.
"""

from __future__ import annotations

import importlib.metadata
import logging
from collections.abc import Mapping, Sequence
from typing import Any

from shared.config import AnyStation, ControllerStation, LoadedStation
from shared.config import stations_by_id

LOG = logging.getLogger(__name__)

Metadata = dict[str, dict[str, str]]


def software_version() -> str:
    """The installed boltwatch version, or ``unknown`` when not installed."""
    try:
        return importlib.metadata.version("boltwatch")
    except importlib.metadata.PackageNotFoundError:
        return "unknown"


def flatten(data: Mapping[str, Any], prefix: str = "") -> dict[str, str]:
    """Nested dict -> ``{"a.b": "value"}``; None becomes an empty string."""
    flat: dict[str, str] = {}
    for name, value in data.items():
        key = f"{prefix}{name}"
        if isinstance(value, Mapping):
            flat.update(flatten(value, f"{key}."))
        else:
            flat[key] = "" if value is None else str(value)
    return flat


class FileMetadata:
    """Builds the metadata records of each new file from the loaded station files."""

    def __init__(
        self,
        loaded: AnyStation | Sequence[AnyStation],
        extra: Mapping[str, Mapping[str, str]] | None = None,
        warn_unknown: bool = True,
    ) -> None:
        stations = [loaded] if isinstance(loaded, LoadedStation | ControllerStation) else loaded
        self._stations = stations_by_id(stations)
        self._extra: Metadata = {name: dict(data) for name, data in (extra or {}).items()}
        self._version = software_version()
        self._warned: set[str] = set()
        self._warn_unknown_stations = warn_unknown

    @property
    def version(self) -> str:
        return self._version

    @property
    def station_ids(self) -> list[str]:
        """The stations with a station file here, in the order given."""
        return list(self._stations)

    def for_file(
        self, station: str, run_id: int | None, tool_id: int | None, program_id: int | None
    ) -> Metadata:
        """The records of a new file of ``station`` (``run_id`` None: between runs)."""
        loaded = self._stations.get(station)
        if loaded is None:
            self._warn_unknown(station)
        records: Metadata = {
            "station": {
                "station": station,
                "tool_id": str(loaded.config.station.tool_id) if loaded else "",
                "station_file": str(loaded.path) if loaded else "",
                "software_version": self._version,
            }
        }
        if run_id is not None:
            records["run"] = {
                "run_id": str(run_id),
                "tool_id": "" if tool_id is None else str(tool_id),
                "program_id": "" if program_id is None else str(program_id),
            }
        if loaded is not None:
            records.update(_configured(loaded, program_id))
        records.update(self._extra)
        return records

    def _warn_unknown(self, station: str) -> None:
        if station in self._warned or not self._warn_unknown_stations:
            return
        self._warned.add(station)
        served = ", ".join(self._stations) or "none"
        LOG.warning(
            "station %s has no station file in this recorder (served: %s); recording its "
            "messages with minimal metadata (no program, no joint)",
            station,
            served,
        )


def _configured(loaded: AnyStation, program_id: int | None) -> Metadata:
    """``program`` and ``joint`` records from the station's own file (a controller station
    has no joint: its ``program`` is the pset's id, name and windows)."""
    records: Metadata = {}
    if program_id is not None:
        try:
            program = loaded.config.program(program_id)
        except KeyError:
            records["program"] = {"id": str(program_id), "error": "not in the station file"}
        else:
            records["program"] = flatten(program.model_dump(mode="json"))
    if isinstance(loaded, LoadedStation):
        joint = loaded.joint if program_id is None else loaded.joint_of(program_id)
        records["joint"] = flatten(joint.model_dump(mode="json"))
    return records
