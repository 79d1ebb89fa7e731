"""What every station file holds, whatever drives its tool: its identity, router and recordings.

A station file is one of two kinds (:mod:`shared.config.station_kinds`): a CAN
station (:mod:`shared.config.station`: ``[can]``, a joint, programs with motor
and hard limits) or a controller station (:mod:`shared.config.controller_station`:
``[openprotocol]``, no ``[can]``). Both have the sections here, read the same
way: ``[station]`` ``id`` and ``tool_id`` (and where it is: ``plant``, ``line``, its
``name`` for people: :class:`StationPlace`), ``[zenoh]`` (the line's router,
reconnection, TLS), ``[recorder]`` (where the recordings go) and ``[spool]``
(store and forward on the edge box). Paths are relative to the station file.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Literal, Protocol, TypeVar

from pydantic import AfterValidator, Field, ValidationInfo, field_validator, model_validator

from shared.config.loading import StrictModel, resolve_relative
from shared.contract.message_fields import MAX_SPINDLES
from shared.errors import ConfigError
from shared.files import FolderError, make_folder

StationId = str
#: the default bound of a spool: about 8 hours of an edge station (SPOOL_BYTES_PER_HOUR,
#: measured by tests/benchmarks/bench_spool.py) with room to spare
SPOOL_MAX_BYTES = 2 * 1024**3

#: a zenoh endpoint: ``<protocol>/<address>[?<metadata>][#<config>]``
ENDPOINT_FORM = re.compile(r"[A-Za-z0-9_-]+/[^?#\s]+(\?[^#\s]*)?(#\S*)?")
#: a name people read (plant, line, station name): one line, no control characters
NO_CONTROL_CHARACTERS = r"^[^\x00-\x1f\x7f]*$"
ENDPOINT_EXPECTED = "expected <protocol>/<address>:<port>, e.g. tcp/127.0.0.1:7447"


def _endpoint(text: str) -> str:
    if not ENDPOINT_FORM.fullmatch(text):
        raise ValueError(f"not a zenoh endpoint: {ENDPOINT_EXPECTED}")
    return text


Endpoint = Annotated[str, AfterValidator(_endpoint)]


@dataclass(frozen=True, slots=True)
class StationPlace:
    """Where a station is in the plant model (plant -> line -> station), as its station
    file's ``[station]`` names it; ``""``: not named. ``name`` is the station's name for
    people (its id is the key)."""

    plant: str = ""
    line: str = ""
    name: str = ""


class StationIdentity(StrictModel):
    """``[station]`` keys of every station: its id on the line, its tool's id, and where it
    is (plant, line) with its name for people."""

    id: StationId = Field(pattern=r"^[A-Za-z0-9_-]{1,64}$", description="key-expression safe")
    tool_id: int = Field(
        ge=0,
        le=65535,
        description="the tool's id: in ToolStatus on CAN; the id a controller station's "
        "runs and wear are counted under",
    )
    plant: str = Field(
        default="",
        max_length=64,
        pattern=NO_CONTROL_CHARACTERS,
        description="the plant the station's line is in, as results and reports name it; '' none",
    )
    line: str = Field(
        default="",
        max_length=64,
        pattern=NO_CONTROL_CHARACTERS,
        description="the line the station is on, as results and reports name it; '' none",
    )
    name: str = Field(
        default="",
        max_length=64,
        pattern=NO_CONTROL_CHARACTERS,
        description="the station's name for people (status, results, the line's page); "
        "'' none: its id is shown",
    )

    spindle_tool_ids: list[Annotated[int, Field(ge=0, le=65535)]] = Field(
        default_factory=list,
        max_length=MAX_SPINDLES,
        description="a multi-spindle station: the tool id of each spindle, in spindle order "
        "(its wear is counted under it); [] (the default): tool_id, tool_id + 1, ...",
    )

    @property
    def place(self) -> StationPlace:
        """Where the station is: its plant, line and name."""
        return StationPlace(self.plant, self.line, self.name)

    def tool_of(self, spindle: int | None) -> int:
        """The tool id of ``spindle`` (1..N; None: the station's one tool, ``tool_id``)."""
        if spindle is None:
            return self.tool_id
        if spindle <= len(self.spindle_tool_ids):
            return self.spindle_tool_ids[spindle - 1]
        return self.tool_id + spindle - 1


class ZenohSection(StrictModel):
    """How a service joins the line: its router, reconnection and TLS.

    TLS: ``docs/how-to/compose-and-tls.md``."""

    mode: Literal["peer", "client"] = "client"
    connect: list[Endpoint] = Field(default_factory=list, description="e.g. tcp/127.0.0.1:7447")
    listen: list[Endpoint] = Field(default_factory=list)
    connect_timeout_s: float | None = Field(
        default=None,
        gt=0,
        description="how long a service waits for its router at start; none: for ever",
    )
    reconnect_period_max_s: float = Field(
        default=2.0,
        gt=0,
        le=60,
        description="longest pause between two attempts to reach a lost router (never gives up)",
    )
    lease_s: float = Field(
        default=10.0,
        ge=1,
        le=600,
        description="how long the line keeps the session of a service that went silent (its "
        "host lost power, its cable was cut) and with it its liveliness tokens: zenoh's "
        "transport/link/tx/lease",
    )
    tls_root_ca: Path | None = Field(
        default=None, description="CA certificate (PEM) of the line, relative to this station file"
    )
    tls_cert: Path | None = Field(
        default=None, description="this service's certificate (PEM), for mutual TLS"
    )
    tls_key: Path | None = Field(default=None, description="its private key (PEM)")

    @field_validator("tls_root_ca", "tls_cert", "tls_key")
    @classmethod
    def _readable_file(cls, path: Path | None, info: ValidationInfo) -> Path | None:
        """Resolve against the station file and fail now, not at the first TLS handshake."""
        if path is None:
            return None
        source = (info.context or {}).get("source")
        resolved = resolve_relative(path, Path(source)) if source is not None else path
        try:
            with resolved.open("rb") as handle:
                handle.read(1)
        except OSError as err:
            raise ValueError(f"cannot read {resolved}: {err.strerror}") from err
        return resolved

    @model_validator(mode="after")
    def _has_somewhere_to_go(self) -> ZenohSection:
        if not self.connect and not self.listen:
            raise ValueError("give connect or listen endpoints (multicast scouting is off)")
        return self

    @model_validator(mode="after")
    def _tls_is_complete(self) -> ZenohSection:
        if (self.tls_cert is None) != (self.tls_key is None):
            raise ValueError("give tls_cert and tls_key together (mutual TLS needs both)")
        uses_tls = any(e.startswith("tls/") for e in [*self.connect, *self.listen])
        if uses_tls and self.tls_root_ca is None:
            raise ValueError("tls/ endpoints need tls_root_ca (the CA that signed the router)")
        if not uses_tls and (self.tls_root_ca or self.tls_cert):
            raise ValueError("tls_* keys are set but no endpoint is tls/ (e.g. tls/host:7447)")
        return self

    @property
    def uses_tls(self) -> bool:
        return self.tls_root_ca is not None


class RecorderSection(StrictModel):
    folder: Path = Field(description="relative to this station file")
    flush_interval_s: float = Field(default=1.0, gt=0, le=60)
    max_file_bytes: int = Field(default=256 * 1024 * 1024, ge=1024 * 1024)
    max_file_duration_s: float = Field(default=600.0, gt=0)
    free_space_reserve_bytes: int = Field(
        default=256 * 1024 * 1024,
        ge=0,
        description="below this much free space on the recordings disk no new run file is "
        "opened (an alert instead); 0: no reserve. The default is the largest a run file "
        "grows to, so a file opened is never cut by a full disk",
    )
    wear_service_threshold: float | None = Field(
        default=None,
        gt=0,
        description="intensity since last service (eq. 69) at which the recorder alerts",
    )
    wear_forecast_days: list[Annotated[float, Field(gt=0, le=365)]] = Field(
        default_factory=lambda: [7.0],
        max_length=5,
        description="horizons in days: a tool forecast to reach wear_service_threshold within "
        "one is announced once (WearForecast on wear/forecast); [] for none",
    )
    results_database: str | None = Field(
        default=None,
        pattern=r"^postgres(ql)?://",
        description="a plant's PostgreSQL for the results store, e.g. "
        "postgresql://boltwatch@db.plant/boltwatch (password: PGPASSFILE); none: "
        "results.sqlite in the recordings folder",
    )


class SpoolSection(StrictModel):
    """Store and forward on the station's edge box (``[spool]``): what the station puts
    toward the line is kept until the line's recorder has it (see :mod:`shared.spool`)."""

    enabled: bool = Field(default=True, description="false: nothing is kept, a cut loses data")
    folder: Path | None = Field(
        default=None,
        description="on the edge box, relative to this station file; none: .spool/ in the "
        "recordings folder",
    )
    max_bytes: int = Field(
        default=SPOOL_MAX_BYTES,
        ge=1024 * 1024,
        description="its bound (the messages as stored): past it the oldest samples go first",
    )
    drain_messages_per_s: float = Field(
        default=100.0,
        gt=0,
        le=100_000,
        description="what it sends again at most, a second (a batch of samples is one)",
    )
    resend_after_s: float = Field(
        default=3.0,
        gt=0,
        le=600,
        description="a message not acknowledged this long after its put is sent again",
    )


def spool_folder(station_file: Path, section: SpoolSection, recordings: Path) -> Path:
    """``spool.folder`` resolved against the station file (none: ``.spool/`` in the
    recordings folder)."""
    if section.folder is None:
        return recordings / ".spool"
    return resolve_relative(section.folder, station_file)


def recordings_folder(station_file: Path, section: RecorderSection) -> Path:
    """``recorder.folder`` resolved against the station file."""
    return resolve_relative(section.folder, station_file)


def make_recordings_folder(station_file: Path, section: RecorderSection) -> Path:
    """The recordings folder, made if missing; ConfigError (file, key, why) if it cannot be.

    Called at a service's start: a folder that can never be made is a
    configuration error, while a disk that fails later is a fault the
    recorder rides out (docs/reference/faults.md).
    """
    folder = recordings_folder(station_file, section)
    try:
        return make_folder(folder)
    except FolderError as err:
        raise ConfigError(f"{station_file}: recorder.folder: {folder}: {err}") from err


class _Numbered(Protocol):
    @property
    def id(self) -> int: ...


Numbered = TypeVar("Numbered", bound=_Numbered)


def check_unique_ids(programs: Sequence[_Numbered], what: str) -> None:
    """ValueError when two of ``programs`` share an id (``what``: "program", "pset")."""
    ids = [program.id for program in programs]
    if len(ids) != len(set(ids)):
        raise ValueError(f"{what} ids must be unique (got {ids})")


def find_program(
    programs: Sequence[Numbered], program_id: int, station_id: str, what: str
) -> Numbered:
    """The one of ``programs`` with ``program_id``; KeyError names the known ids."""
    for program in programs:
        if program.id == program_id:
            return program
    known = ", ".join(str(program.id) for program in programs) or "none"
    raise KeyError(f"no {what} {program_id} in station {station_id} (known: {known})")
