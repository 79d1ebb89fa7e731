"""A line: several stations served together, and stations derived from one.

Line services (predictor, recorder) take several station files; they must
agree on where the line's zenoh router is and name each station once
(:func:`load_line`: CAN stations, for the predictor and ``up``;
:func:`load_any_line`: either kind, for the recorder, the dashboard and
``health``). ``boltwatch up --stations N`` derives N isolated
simulated stations from one station file (:func:`derive_stations`):

- ids: the base id's trailing number counts up (``st1`` -> ``st1, st2, ...``;
  ``press`` -> ``press1, press2, ...``; ``st5`` -> ``st5, st6, ...``);
- CAN: the same interface and channel, UDP multicast port ``base + i``
  (i = 0..N-1), so each station has its own simulated bus;
- ``station.tool_id`` = base + i, ``rig.seed`` = base + i (unset stays unset:
  a fresh seed per process);
- the rest (router and its TLS files, joint, DBC, programs and their joints,
  predictor, recorder folder) is the base file's, with relative paths made
  absolute because the derived files live elsewhere (in the run's log folder).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any, TypeVar

from shared.config.loading import read_toml, resolve_relative
from shared.config.station import LoadedStation, load_station
from shared.config.station_kinds import AnyStation, load_any_station
from shared.config.toml_writer import dumps
from shared.errors import ConfigError

MAX_PORT = 65535
MAX_TOOL_ID = 65535

#: a loaded station, of one kind or of either
StationT = TypeVar("StationT", bound=AnyStation)


def stations_by_id(stations: Sequence[StationT]) -> dict[str, StationT]:
    """Station id -> its file; ConfigError naming both files when an id repeats."""
    seen: dict[str, StationT] = {}
    for station in stations:
        twin = seen.get(station.station_id)
        if twin is not None:
            raise ConfigError(
                f"{twin.path} and {station.path}: station.id: both are station "
                f"{station.station_id!r}; one process serves a station once"
            )
        seen[station.station_id] = station
    return seen


def load_line(paths: Sequence[Path]) -> list[LoadedStation]:
    """Load every CAN station file of a line service; one station id per file, one router.

    Two files with the same station id, or with different ``[zenoh]`` sections
    (a line process has one zenoh session), are a ConfigError naming both files.
    """
    if not paths:
        raise ConfigError("no station file given")
    return _one_line([load_station(Path(path)) for path in paths])


def load_any_line(paths: Sequence[Path]) -> list[AnyStation]:
    """:func:`load_line` for stations of either kind (CAN or controller)."""
    if not paths:
        raise ConfigError("no station file given")
    return _one_line([load_any_station(Path(path)) for path in paths])


def _one_line(stations: list[StationT]) -> list[StationT]:
    """``stations``, each id once and all on one router; else ConfigError naming both files."""
    first = stations[0]
    stations_by_id(stations)
    for station in stations:
        if station.config.zenoh != first.config.zenoh:
            raise ConfigError(
                f"{first.path} and {station.path}: zenoh: the sections differ "
                f"({first.config.zenoh.model_dump()} vs {station.config.zenoh.model_dump()}); "
                "stations served by one process must use the same zenoh settings"
            )
    return stations


def derived_ids(base_id: str, count: int) -> list[str]:
    """``st1`` -> ``st1..stN``; ``press`` -> ``press1..pressN`` (see the module docstring)."""
    match = re.fullmatch(r"(.*?)(\d+)", base_id)
    prefix, first = (match.group(1), int(match.group(2))) if match else (base_id, 1)
    return [f"{prefix}{first + i}" for i in range(count)]


def check_derivable(base_path: Path, count: int) -> tuple[LoadedStation, list[str]]:
    """(the base station, the derived ids) of ``count`` stations from ``base_path``;
    ConfigError naming the file and key when they cannot be derived. Writes nothing."""
    if count < 1:
        raise ConfigError(f"--stations must be at least 1 (got {count})")
    base = load_station(base_path)
    config = base.config
    if config.can.interface == "socketcan" and count > 1:
        raise ConfigError(
            f"{base_path}: can.interface: 'socketcan' is one real bus; derive simulated "
            "stations from a udp_multicast (or virtual) station file"
        )
    if config.can.interface == "udp_multicast":
        base_port = config.can.port
        if base_port is None:
            raise ConfigError(f"{base_path}: can.port: needed to derive one bus per station")
        if base_port + count - 1 > MAX_PORT:
            raise ConfigError(
                f"{base_path}: can.port: {base_port} + {count - 1} stations exceeds {MAX_PORT}"
            )
    if config.station.tool_id + count - 1 > MAX_TOOL_ID:
        raise ConfigError(
            f"{base_path}: station.tool_id: {config.station.tool_id} + {count - 1} "
            f"stations exceeds {MAX_TOOL_ID}"
        )
    ids = derived_ids(base.station_id, count)  # count is bounded by the tool ids now
    for id_ in ids:
        if len(id_) > 64:
            raise ConfigError(f"{base_path}: station.id: derived id {id_!r} is too long")
    return base, ids


def derive_stations(base_path: Path, count: int, folder: Path) -> list[Path]:
    """Write ``count`` station files derived from ``base_path`` into ``folder``.

    Returns their paths (``folder/<id>.toml``), each already checked with
    :func:`load_station` and all together with :func:`load_line`.
    """
    base, ids = check_derivable(base_path, count)
    raw = read_toml(base_path)
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for i, station_id in enumerate(ids):
        document = _derived_document(raw, base, i, station_id)
        path = folder / f"{station_id}.toml"
        path.write_text(
            f"# Derived by boltwatch up --stations {count} from {base_path.resolve()}\n"
            + dumps(document)
        )
        paths.append(path)
    load_line(paths)
    return paths


def _derived_document(
    raw: dict[str, Any], base: LoadedStation, index: int, station_id: str
) -> dict[str, Any]:
    config = base.config
    document = dict(raw)  # the sections changed below are new dicts: raw stays as read
    document["station"] = {
        **raw["station"],
        "id": station_id,
        "tool_id": config.station.tool_id + index,
        "joint": str(base.joint_path.resolve()),
    }
    can = {**raw["can"], "dbc": str(base.dbc_path.resolve())}
    if config.can.interface == "udp_multicast" and config.can.port is not None:
        can["port"] = config.can.port + index
    elif config.can.interface == "virtual":
        can["channel"] = f"{config.can.channel}-{station_id}"
    document["can"] = can
    if config.rig.seed is not None:
        document["rig"] = {**raw.get("rig", {}), "seed": config.rig.seed + index}
    document["recorder"] = {**raw["recorder"], "folder": str(base.recordings_folder.resolve())}
    tls = {
        key: str(path.resolve())
        for key in ("tls_root_ca", "tls_cert", "tls_key")
        if (path := getattr(config.zenoh, key)) is not None  # resolved when loaded
    }
    document["zenoh"] = {**raw["zenoh"], **tls}
    document["programs"] = [
        {**program, "joint": str(resolve_relative(Path(program["joint"]), base.path))}
        if "joint" in program
        else program
        for program in raw["programs"]
    ]
    return document
