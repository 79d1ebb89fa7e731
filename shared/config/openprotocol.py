"""The ``[openprotocol]`` section of a station file: a tightening controller over Open Protocol.

A station whose tool is driven by a controller that speaks Atlas Copco's Open
Protocol (TCP, port 4545) has a bridge (``boltwatch serve openprotocol
--config STATION``) instead of an acquisition: it connects to the controller
as an integrator and publishes what the controller says on the station's
channels. The section is optional; where it is, ``host`` is required and
every other key has a default. Where the public layouts leave room or real
controllers differ, a key says which form this controller uses
(``trace_byte_order``, ``header_fill``).

``[rig.openprotocol]`` (:class:`RigOpenProtocolSection`) is the other side:
how the simulated controller of ``services/rig`` behaves toward a bridge.
"""

from __future__ import annotations

import zoneinfo
from typing import Literal

from pydantic import Field, field_validator, model_validator

from shared.config.loading import StrictModel

#: a controller drops a link silent this long (the public specification's 15 s)
CONTROLLER_LINK_TIMEOUT_S = 15.0


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
    trace_byte_order: Literal["big", "little"] = Field(
        default="big", description="byte order of MID 0900 samples"
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
