"""The station files one recorder serves: they must agree on its folder, ``[recorder]`` and
``[retention]`` (one folder, one policy)."""

from __future__ import annotations

from collections.abc import Sequence

from services.recorder.live.run_files import FileLimits
from shared.config import AnyStation, ControllerStation, LoadedStation
from shared.errors import ConfigError
from shared.files import real_path
from shared.retention import retention_scopes


def limits_of(loaded: AnyStation) -> FileLimits:
    section = loaded.config.recorder
    return FileLimits(
        flush_interval_ns=round(section.flush_interval_s * 1e9),
        max_file_bytes=section.max_file_bytes,
        max_file_duration_ns=round(section.max_file_duration_s * 1e9),
        free_space_reserve_bytes=section.free_space_reserve_bytes,
    )


def served_stations(loaded: AnyStation | Sequence[AnyStation]) -> list[AnyStation]:
    """The station files of one recorder (CAN or controller stations); ConfigError when their
    [recorder] or [retention] sections differ."""
    stations = [loaded] if isinstance(loaded, LoadedStation | ControllerStation) else list(loaded)
    if not stations:
        raise ConfigError("the recorder needs at least one station file")
    first = stations[0]
    settings = first.config.recorder.model_dump(exclude={"folder"})
    for other in stations[1:]:
        if real_path(other.recordings_folder) != real_path(first.recordings_folder):
            raise ConfigError(
                f"{other.path}: recorder.folder: {other.recordings_folder} differs from "
                f"{first.recordings_folder} of {first.path}; one recorder writes one folder"
            )
        for name, value in other.config.recorder.model_dump(exclude={"folder"}).items():
            if settings[name] != value:
                raise ConfigError(
                    f"{other.path}: recorder.{name}: {value} differs from {settings[name]} "
                    f"of {first.path}; one recorder has one [recorder] section"
                )
    retention_scopes(stations)  # the same folder: one [retention] section, or a ConfigError
    return stations
