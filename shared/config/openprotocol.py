"""The ``[openprotocol]`` section of a station file: a tightening controller over Open Protocol.

A station whose tool is driven by a controller that speaks Atlas Copco's Open
Protocol (TCP, port 4545) has a bridge (``boltwatch serve openprotocol
--config STATION``) instead of an acquisition: it connects to the controller
as an integrator and publishes what the controller says on the station's
channels. The section is optional; where it is, ``host`` is required and
every other key has a default. Where the public layouts leave room or real
controllers differ, a key says which form this controller uses
(``trace_byte_order``, ``header_fill``). A simulated controller
(``[rig.openprotocol]``) writes its 0900 samples in ``trace_byte_order``
(big for ``auto``).

``[rig.openprotocol]`` (:class:`RigOpenProtocolSection`) is the other side:
how the simulated controller of ``services/rig`` behaves toward a bridge
(``boltwatch serve rig --controller openprotocol``), which a real controller
keeps in its own settings:

- ``ack_timeout_s`` / ``result_resends``: a pushed result (MID 0061) not
  acknowledged (0062) within ``ack_timeout_s`` is sent again, at most
  ``result_resends`` times; then the link is dropped with every subscription
  (3 re-sends as controller manuals say: the Sturtevant Richmont
  Global 400 manual's Open Protocol settings give retries 3, ack timeout 10 s).
- ``link_timeout_s``: a link silent this long is dropped (15 s, the specification).
- ``mirror_keep_alive``: answer an integrator's keep-alive (9999) with one
  (most controllers do); false: say nothing (some do; both are real).
- ``results_kept``: how many tightenings the controller keeps, the newest, to
  serve by id (0064 -> 0065) while nobody is connected or after.
- ``max_result_revision``: the highest 0061/0065 revision it speaks (1 plays
  an older controller: a request for 2 gets 0004 error 97).
- ``vin_pattern``: the part id (VIN) of each tightening, a Python format text
  naming ``{station}``, ``{tool_id}``, ``{tightening_id}``, ``{batch_counter}``
  (at most 25 characters filled with the widest values and an 8-character
  station id: the VIN field of 0061; a longer station id is cut when filled).
- ``batch_size``: OK tightenings per batch (the batch counter counts them and
  starts again at 1 after a complete batch); 0: no batch.
- ``last_calibration`` / ``last_service``: the dates tool data (0041) gives;
  none: the day the controller started.
"""

from __future__ import annotations

import datetime as dt
import string
import zoneinfo
from typing import Literal

from pydantic import Field, field_validator, model_validator

from shared.config.loading import StrictModel

#: a controller drops a link silent this long (the public specification's 15 s)
CONTROLLER_LINK_TIMEOUT_S = 15.0
#: the VIN field of MID 0061 (25 characters)
VIN_CHARS = 25
#: the widest value of each name a VIN pattern may use (a station id: 8 characters kept)
VIN_WIDEST: dict[str, str | int] = {
    "station": "x" * 8,
    "tool_id": 65535,
    "tightening_id": 9_999_999_999,
    "batch_counter": 9999,
}


class OpenProtocolSection(StrictModel):
    """How the bridge reaches its controller and reads what it sends."""

    host: str = Field(
        min_length=1,
        max_length=253,
        pattern=r"^[A-Za-z0-9.:_-]+$",
        description="the controller's IP address or host name",
    )
    port: int = Field(default=4545, ge=1, le=65535, description="the controller's TCP port")
    keep_alive_s: float = Field(
        default=10.0,
        gt=0,
        lt=CONTROLLER_LINK_TIMEOUT_S,
        description="MID 9999 at least this often: controllers drop a link silent for 15 s",
    )
    reconnect_min_s: float = Field(
        default=1.0, gt=0, description="first pause before connecting again after a lost link"
    )
    reconnect_max_s: float = Field(
        default=30.0, gt=0, le=3600, description="longest pause between two connection attempts"
    )
    result_revision: int = Field(
        default=2,
        ge=1,
        le=999,
        description="highest revision of MID 0061 to ask for (lower ones on error 97)",
    )
    trace_byte_order: Literal["auto", "big", "little"] = Field(
        default="auto",
        description="byte order of MID 0900 samples; auto: the one whose curves agree with "
        "their results (big tried first), found once and kept",
    )
    header_fill: Literal["spaces", "zeros"] = Field(
        default="spaces", description="how the controller fills unused header fields"
    )
    timezone: str = Field(
        default="UTC",
        min_length=1,
        description="IANA name of the time zone the controller's clock runs in",
    )
    traces: bool = Field(
        default=True, description="subscribe to MID 0900 (torque and angle curves)"
    )
    multi_spindle: bool = Field(
        default=False,
        description="the controller is a multi-spindle system (a sync master, a station "
        "controller): subscribe to its multi-spindle status and results (MIDs 0090, 0100) "
        "and publish each cycle's common result; a CAN station file of several spindles "
        "([station] spindles) says so by itself",
    )

    @field_validator("timezone")
    @classmethod
    def _known_timezone(cls, name: str) -> str:
        try:
            zoneinfo.ZoneInfo(name)
        except (zoneinfo.ZoneInfoNotFoundError, ValueError) as err:
            raise ValueError(
                f"not a time zone zoneinfo knows ({type(err).__name__}); "
                "expected an IANA name, e.g. UTC or Europe/Berlin"
            ) from err
        return name

    @model_validator(mode="after")
    def _reconnect_range(self) -> OpenProtocolSection:
        if self.reconnect_min_s > self.reconnect_max_s:
            raise ValueError(
                f"reconnect_min_s {self.reconnect_min_s:g} s is above reconnect_max_s "
                f"{self.reconnect_max_s:g} s"
            )
        return self


class RigOpenProtocolSection(StrictModel):
    """How the simulated controller treats a bridge (``[rig.openprotocol]``)."""

    ack_timeout_s: float = Field(
        default=5.0,
        gt=0,
        le=60,
        description="how long it waits for MID 0062 before sending a result again",
    )
    link_timeout_s: float = Field(
        default=CONTROLLER_LINK_TIMEOUT_S,
        gt=0,
        le=600,
        description="it drops a link silent this long",
    )
    result_resends: int = Field(
        default=3, ge=0, le=10, description="re-sends of an unacknowledged 0061, then a drop"
    )
    mirror_keep_alive: bool = Field(
        default=True, description="answer a keep-alive (9999) with one; false: stay silent"
    )
    results_kept: int = Field(
        default=1000,
        ge=1,
        le=100_000,
        description="tightenings kept (with their traces) to serve by id (0064)",
    )
    max_result_revision: int = Field(
        default=2, ge=1, le=2, description="highest 0061/0065 revision the controller speaks"
    )
    vin_pattern: str = Field(
        default="SIM{tightening_id:010d}",
        description="part id of each tightening: {station} {tool_id} {tightening_id} "
        "{batch_counter}",
    )
    batch_size: int = Field(default=10, ge=0, le=9999, description="OK tightenings per batch")
    last_calibration: dt.date | None = Field(default=None, description="none: the start day")
    last_service: dt.date | None = Field(default=None, description="none: the start day")

    @field_validator("vin_pattern")
    @classmethod
    def _vin_pattern_fits(cls, pattern: str) -> str:
        try:
            parsed = list(string.Formatter().parse(pattern))
        except ValueError as err:
            raise ValueError(f"not a format text: {err}") from err
        names = {name for _, name, _, _ in parsed if name is not None}
        unknown = names - set(VIN_WIDEST)
        if unknown:
            raise ValueError(
                f"names {', '.join(repr(n) for n in sorted(unknown))}; expected only "
                f"{', '.join(VIN_WIDEST)}"
            )
        try:
            widest = pattern.format(**VIN_WIDEST)
        except (KeyError, IndexError, ValueError) as err:
            raise ValueError(f"cannot be filled in: {err}") from err
        if not widest.isascii() or not widest.isprintable():
            raise ValueError("must give printable ASCII")
        if len(widest) > VIN_CHARS:
            raise ValueError(
                f"gives {len(widest)} characters at its widest, more than the {VIN_CHARS} "
                "of the VIN field of MID 0061"
            )
        return pattern

    def vin(self, station: str, tool_id: int, tightening_id: int, batch_counter: int) -> str:
        """The part id of one tightening, cut to the 25 characters of the VIN field."""
        text = self.vin_pattern.format(
            station=station,
            tool_id=tool_id,
            tightening_id=tightening_id,
            batch_counter=batch_counter,
        )
        return text[:VIN_CHARS]
