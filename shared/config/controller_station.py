"""The controller station file: a station whose tool an Open Protocol controller drives.

A plant's controller (Atlas Copco, Desoutter, ...) runs its tool on its own
psets, targets and limits; boltwatch only listens, through the bridge
(``boltwatch serve openprotocol``). Its station file says what boltwatch
needs for that, and nothing of a tool boltwatch would read over CAN or
simulate (``config/controller-station.toml``)::

    [station]       id, tool_id                      required
    [zenoh]         the line's router                required
    [openprotocol]  host (port, timers, ...)         required
    [recorder]      folder (...)                     required
    [quality]       the recorder's quality alert     optional
    [retention]     how long recordings are kept     optional
    [[programs]]    the controller's psets           optional: id (1-999, the pset
                    number), name, and the windows torque_min_nm / torque_max_nm,
                    angle_min_deg / angle_max_deg

**Which kind a file is**: ``[openprotocol]`` without ``[can]`` is a
controller station (:func:`is_controller_station`). A file with ``[can]``
is a CAN station (:mod:`shared.config.station`), validated as strictly as
ever, with or without ``[openprotocol]``: the rig's simulated controller
(``boltwatch up --controller openprotocol``) plays a CAN station's joint and
programs, and the bridge reads the same file.

**Refused in a controller station**, naming the file and each key, before
anything else is checked: the keys of a CAN station that would do nothing
here (``station.joint``, ``station.has_force_sensor``, ``[rig]``,
``[predictor]``, a pset's targets, motor speed, hard limits and joint), and
preload windows (``force_min_n`` / ``force_max_n``: a controller reports
torque and angle, no preload). A plant engineer who writes one of them
expects it to act; silence would let them believe it does.

**What a pset's entry does**: its name names the pset's runs (results,
recordings, status); its windows judge the pset's runs (each figure with a
bound here; the others against the controller's own limits, MID 0061) and
are kept with each run's recording (the ``program`` metadata record). A
result is OK only where the controller said OK and every figure is in its
window; where they disagree it is NOK and says so
(:mod:`shared.quality.controller_result`). ``boltwatch inspect`` draws the
controller's own window and target.

**Sensor range**: the contract's (:data:`shared.contract.sensor_range.CONTRACT_RANGE`,
the range of ``config/can/station.dbc``: torque ±8388 Nm, angle ±83886 deg):
a controller station has no DBC, and that range holds every tool a
controller drives. The recorder refuses samples beyond it, the wear ledger
bounds a run's intensity by its torque top, windows must lie within it.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pydantic import Field, model_validator

from shared.config.common_sections import (
    RecorderSection,
    SpoolSection,
    StationIdentity,
    ZenohSection,
    check_unique_ids,
    find_program,
    make_recordings_folder,
    recordings_folder,
    spool_folder,
)
from shared.config.loading import StrictModel, read_toml, validate
from shared.config.openprotocol import OpenProtocolSection
from shared.config.program_windows import ProgramWindows
from shared.config.quality import QualitySection
from shared.config.retention import RetentionSection
from shared.contract import CONTRACT_RANGE, SensorRange
from shared.errors import ConfigError

#: what a controller station's samples can hold (see the module docstring)
CONTROLLER_RANGE: SensorRange = CONTRACT_RANGE

_WHAT = "not used by a controller station ([openprotocol] without [can])"
#: keys of a CAN station refused in a controller station: (table, key or None: the
#: whole table) -> why it does nothing there
CAN_ONLY: dict[tuple[str, str | None], str] = {
    ("station", "joint"): "the controller's joint is neither simulated nor modelled",
    ("station", "has_force_sensor"): "a controller reports torque and angle, no preload",
    ("rig", None): "the simulated tool's settings; a controller station's tool is real "
    "(the simulated controller plays a CAN station file, e.g. config/station.toml)",
    ("predictor", None): "the controller stops its own tool; the bridge replays each "
    "tightening, torque only, with the predictor's defaults",
}
#: keys of a CAN station's ``[[programs]]`` entry refused in a pset's, and why
PSET_CAN_ONLY: dict[str, str] = {
    **dict.fromkeys(
        (
            "target_force_n",
            "target_torque_nm",
            "motor_speed_rad_s",
            "start_force_n",
            "max_torque_nm",
            "max_force_n",
            "max_angle_deg",
            "max_time_s",
            "joint",
        ),
        "the controller keeps its pset's target, speed and limits itself "
        "(a pset here has id, name and torque and angle windows)",
    ),
    **dict.fromkeys(
        ("force_min_n", "force_max_n"), "a controller reports torque and angle, no preload"
    ),
}


def is_controller_station(data: dict[str, Any]) -> bool:
    """Whether a station file's TOML is a controller station's: ``[openprotocol]``, no ``[can]``."""
    return "openprotocol" in data and "can" not in data


class ControllerProgram(ProgramWindows):
    """A pset of the controller: its number, its name, the windows kept with its runs."""

    id: int = Field(ge=1, le=999, description="the pset number (MID 0061: three digits)")
    name: str = Field(description="how the pset's runs are named (results, status, recordings)")

    @model_validator(mode="after")
    def _windows_within_the_range(self) -> ControllerProgram:
        beyond = self.windows_beyond(CONTROLLER_RANGE)
        if beyond is not None:
            raise ValueError(beyond)
        return self


class ControllerStationConfig(StrictModel):
    """A controller station's file (see the module docstring)."""

    station: StationIdentity
    zenoh: ZenohSection
    openprotocol: OpenProtocolSection
    recorder: RecorderSection
    spool: SpoolSection = SpoolSection()
    quality: QualitySection = QualitySection()
    retention: RetentionSection = RetentionSection()
    programs: list[ControllerProgram] = Field(
        default_factory=list, description="the controller's psets, to name their runs"
    )

    @model_validator(mode="after")
    def _program_ids_unique(self) -> ControllerStationConfig:
        check_unique_ids(self.programs, "pset")
        return self

    def program(self, program_id: int) -> ControllerProgram:
        """The pset with ``program_id``; KeyError names the known ids."""
        return find_program(self.programs, program_id, self.station.id, "pset")


class ControllerStation:
    """A validated controller station file: what its bridge, recorder and tools read."""

    def __init__(self, path: Path, config: ControllerStationConfig) -> None:
        self.path = path
        self.config = config
        #: what its samples can hold: the contract's range (no DBC)
        self.sensor_range = CONTROLLER_RANGE

    @property
    def station_id(self) -> str:
        return self.config.station.id

    @property
    def spool_folder(self) -> Path:
        return spool_folder(self.path, self.config.spool, self.recordings_folder)

    @property
    def recordings_folder(self) -> Path:
        return recordings_folder(self.path, self.config.recorder)

    def make_recordings_folder(self) -> Path:
        """The recordings folder, made if missing; ConfigError (file, key, why) if it cannot be."""
        return make_recordings_folder(self.path, self.config.recorder)


def can_only_keys(data: dict[str, Any]) -> list[tuple[str, str]]:
    """(key, why) of every key of ``data`` that only a CAN station uses, in file order."""
    found: list[tuple[str, str]] = []
    for (table, key), why in CAN_ONLY.items():
        section = data.get(table)
        if key is None and table in data:
            found.append((table, why))
        elif key is not None and isinstance(section, dict) and key in section:
            found.append((f"{table}.{key}", why))
    programs = data.get("programs")
    for index, entry in enumerate(programs if isinstance(programs, list) else []):
        if isinstance(entry, dict):
            found += [
                (f"programs[{index}].{key}", PSET_CAN_ONLY[key])
                for key in entry
                if key in PSET_CAN_ONLY
            ]
    return found


def refuse_can_only_keys(data: dict[str, Any], path: Path) -> None:
    """ConfigError naming every key of a CAN station in a controller station's ``data``;
    keys with the same reason are named together."""
    found = can_only_keys(data)
    if not found:
        return
    by_reason: dict[str, list[str]] = {}
    for key, why in found:
        by_reason.setdefault(why, []).append(key)
    parts = [
        f"{', '.join(keys)}: {_WHAT}: {why}; remove {'it' if len(keys) == 1 else 'them'}"
        for why, keys in by_reason.items()
    ]
    raise ConfigError(f"{path}: " + "; ".join(parts))


def load_controller_station(path: Path, data: dict[str, Any] | None = None) -> ControllerStation:
    """Load a controller station file (``data``: its TOML, when read already); every error
    names the file and the key."""
    path = Path(path)
    data = read_toml(path) if data is None else data
    if not is_controller_station(data):
        raise ConfigError(
            f"{path}: openprotocol: a controller station needs [openprotocol] (the controller's "
            "host) and no [can]"
        )
    refuse_can_only_keys(data, path)
    return ControllerStation(path, validate(ControllerStationConfig, data, path))
