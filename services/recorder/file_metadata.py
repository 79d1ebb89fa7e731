"""The MCAP metadata records of a recording: who recorded what, with which settings.

Each file carries (MCAP metadata records, string to string):

``station``   station id, tool id, station file, recorder software version
``run``       run id, tool id and program id as the tool reported them (run files)
``program``   the program's parameters from the station file (run files)
``joint``     the joint parameters (JointConfig, nested keys dotted)

Files of a station other than the configured one get ``station`` only: its
configuration is not known here.
"""

from __future__ import annotations

import importlib.metadata
from collections.abc import Mapping
from typing import Any

from shared.config import LoadedStation

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
    """Builds the metadata records of each new file from the loaded station."""

    def __init__(self, loaded: LoadedStation) -> None:
        self._loaded = loaded
        self._version = software_version()

    @property
    def version(self) -> str:
        return self._version

    def for_file(
        self, station: str, run_id: int | None, tool_id: int | None, program_id: int | None
    ) -> Metadata:
        """The records of a new file of ``station`` (``run_id`` None: between runs)."""
        config = self._loaded.config
        own = station == config.station.id
        records: Metadata = {
            "station": {
                "station": station,
                "tool_id": str(config.station.tool_id) if own else "",
                "station_file": str(self._loaded.path) if own else "",
                "software_version": self._version,
            }
        }
        if run_id is not None:
            records["run"] = {
                "run_id": str(run_id),
                "tool_id": "" if tool_id is None else str(tool_id),
                "program_id": "" if program_id is None else str(program_id),
            }
        if not own:
            return records
        if program_id is not None:
            try:
                program = config.program(program_id)
            except KeyError:
                records["program"] = {"id": str(program_id), "error": "not in the station file"}
            else:
                records["program"] = flatten(program.model_dump(mode="json"))
        records["joint"] = flatten(self._loaded.joint.model_dump(mode="json"))
        return records
