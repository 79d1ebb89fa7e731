"""Tool data: 0040 request, 0041 reply.

0041, parameter ids 01..: rev 1: tool serial number (14), tool number of
tightenings (10), last calibration date (19), controller serial number (10);
rev 2 adds calibration value (6, hundredths of Nm), last service date (19),
tightenings since service (10), tool type (2), motor size (2), open end data
(3: use open end, tightening direction, motor rotation), controller software
version (19); rev 3 adds tool max torque (6, hundredths), gear ratio (6,
hundredths), tool full speed (6, hundredths); rev 4 primary tool (2); rev 5
tool model (12). Lengths: rev 1: 81, rev 2: 156, rev 3: 180, rev 4: 184, rev 5:
198 bytes (header included).

Sources: OpenProtocolInterpreter ``Tool/Mid0041.cs`` (offsets, parameter
ids) and the Rust crate ``messages/tool.rs``. They disagree: the Rust crate
writes the fields without parameter ids and stops rev 2 at tool type;
OpenProtocolInterpreter's offsets (and the specification's "01".."11") carry
ids and continue to the controller software version: we follow it.
0040 has no data up to rev 5 (rev 6 adds a tool number: not implemented).
Revisions 3 to 5 of 0041 as OpenProtocolInterpreter's offsets give them
(``Mid0041.cs``, fields 12-16), which the specification's text agrees with.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from shared.openprotocol.fields import Layout, LayoutMessage, Spec, numbered

_TOOL_1 = (
    Spec("tool_serial", "tool serial number", 14, "text"),
    Spec("tightenings", "tool number of tightenings", 10),
    Spec("last_calibration", "last calibration date", 19, "timestamp"),
    Spec("controller_serial", "controller serial number", 10, "text"),
)
_TOOL_2 = (
    *_TOOL_1,
    Spec("calibration_value_nm", "calibration value", 6, "centi"),
    Spec("last_service", "last service date", 19, "timestamp"),
    Spec("tightenings_since_service", "tightenings since service", 10),
    Spec("tool_type", "tool type", 2),
    Spec("motor_size", "motor size", 2),
    Spec("open_end_data", "open end data", 3, "text"),
    Spec("controller_software_version", "controller software version", 19, "text"),
)
_TOOL_3 = (
    *_TOOL_2,
    Spec("max_torque_nm", "tool max torque", 6, "centi"),
    Spec("gear_ratio", "gear ratio", 6, "centi"),
    Spec("full_speed_rpm", "tool full speed", 6, "centi"),
)
_TOOL_4 = (*_TOOL_3, Spec("primary_tool", "primary tool", 2))
_TOOL_5 = (*_TOOL_4, Spec("tool_model", "tool model", 12, "text"))


@dataclass(frozen=True, slots=True, kw_only=True)
class ToolDataRequest(LayoutMessage):
    """0040: ask 0041 at ``revision``."""

    MID: ClassVar[int] = 40
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: (), 2: (), 3: (), 4: (), 5: ()}
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class ToolData(LayoutMessage):
    """0041: the tool's serial, tightening counts, calibration and service."""

    MID: ClassVar[int] = 41
    LAYOUTS: ClassVar[dict[int, Layout]] = {
        1: numbered(*_TOOL_1),
        2: numbered(*_TOOL_2),
        3: numbered(*_TOOL_3),
        4: numbered(*_TOOL_4),
        5: numbered(*_TOOL_5),
    }
    tool_serial: str
    tightenings: int
    last_calibration: str
    controller_serial: str
    # revision 2
    calibration_value_nm: float | None = None
    last_service: str | None = None
    tightenings_since_service: int | None = None
    tool_type: int | None = None
    motor_size: int | None = None
    open_end_data: str | None = None
    controller_software_version: str | None = None
    # revision 3
    max_torque_nm: float | None = None
    gear_ratio: float | None = None
    full_speed_rpm: float | None = None
    # revision 4, 5
    primary_tool: int | None = None
    tool_model: str | None = None
    revision: int = 1
