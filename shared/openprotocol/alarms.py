"""Alarms: 0070 subscribe ... 0077 alarm status acknowledge.

=====  ===============================  ===========================================
MID    class                            data (parameter ids 01.. unless said)
=====  ===============================  ===========================================
0070   AlarmSubscribe                   none
0071   Alarm                            error code (4 at rev 1, 5 at rev 2),
                                        controller ready (1), tool ready (1),
                                        time (19); rev 2: + alarm text (50)
0072   AlarmAcknowledge                 none
0073   AlarmUnsubscribe                 none
0074   AlarmAcknowledgedOnController    error code (4 at rev 1, 5 at rev 2), no id
0075   AlarmAcknowledgedOnControllerAck none
0076   AlarmStatus                      alarm status (1), error code (4 / 5),
                                        controller ready (1), tool ready (1), time (19)
0077   AlarmStatusAck                   none
=====  ===============================  ===========================================

Sources: node-open-protocol ``src/mid/0071.js``, ``0076.js`` (rev 1 and 2)
and OpenProtocolInterpreter ``Alarm/Mid007*.cs`` agree; the Rust crate
writes 0071 without parameter ids (not followed). Error codes are kept as
text: the specification gives them as characters, not a number.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from shared.openprotocol.fields import Layout, LayoutMessage, Spec, numbered


def _code(width: int) -> Spec:
    return Spec("error_code", "error code", width, "text")


_READY = (
    Spec("controller_ready", "controller ready status", 1, "flag"),
    Spec("tool_ready", "tool ready status", 1, "flag"),
    Spec("time", "time", 19, "timestamp"),
)
_TEXT = Spec("alarm_text", "alarm text", 50, "text")
_STATUS = Spec("alarm_active", "alarm status", 1, "flag")


@dataclass(frozen=True, slots=True, kw_only=True)
class AlarmSubscribe(LayoutMessage):
    MID: ClassVar[int] = 70
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: (), 2: ()}
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class Alarm(LayoutMessage):
    """0071: an alarm appeared on the controller."""

    MID: ClassVar[int] = 71
    LAYOUTS: ClassVar[dict[int, Layout]] = {
        1: numbered(_code(4), *_READY),
        2: numbered(_code(5), *_READY, _TEXT),
    }
    error_code: str
    controller_ready: bool
    tool_ready: bool
    time: str
    alarm_text: str | None = None  # rev 2
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class AlarmAcknowledge(LayoutMessage):
    MID: ClassVar[int] = 72
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: ()}
    ANY_REVISION: ClassVar[bool] = True
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class AlarmUnsubscribe(LayoutMessage):
    MID: ClassVar[int] = 73
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: ()}
    ANY_REVISION: ClassVar[bool] = True
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class AlarmAcknowledgedOnController(LayoutMessage):
    """0074: the alarm ``error_code`` was acknowledged on the controller."""

    MID: ClassVar[int] = 74
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: (_code(4),), 2: (_code(5),)}
    error_code: str
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class AlarmAcknowledgedOnControllerAck(LayoutMessage):
    MID: ClassVar[int] = 75
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: ()}
    ANY_REVISION: ClassVar[bool] = True
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class AlarmStatus(LayoutMessage):
    """0076: whether an alarm is active, sent after 0070."""

    MID: ClassVar[int] = 76
    LAYOUTS: ClassVar[dict[int, Layout]] = {
        1: numbered(_STATUS, _code(4), *_READY),
        2: numbered(_STATUS, _code(5), *_READY),
    }
    alarm_active: bool
    error_code: str
    controller_ready: bool
    tool_ready: bool
    time: str
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class AlarmStatusAck(LayoutMessage):
    MID: ClassVar[int] = 77
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: ()}
    ANY_REVISION: ClassVar[bool] = True
    revision: int = 1
