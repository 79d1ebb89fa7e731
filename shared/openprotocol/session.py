"""Session messages: communication start/stop, command error/accepted, keep-alive.

=====  ===========================  ======================================
MID    class                        data
=====  ===========================  ======================================
0001   CommunicationStart           none (revision = the 0002 revision asked)
0002   CommunicationStartAck        rev 1: 01 cell id (4), 02 channel id (2),
                                    03 controller name (25); rev 2: + 04
                                    supplier code (3); rev 3: + 05 Open
                                    Protocol version (19), 06 controller
                                    software version (19), 07 tool software
                                    version (19)
0003   CommunicationStop            none
0004   CommandError                 MID refused (4) + error code: 2 digits at
                                    rev 1, 3 digits at rev 2 (no parameter ids)
0005   CommandAccepted              MID accepted (4); also the acknowledge of a
                                    pushed 0900 (see :mod:`.subscriptions`)
9999   KeepAlive                    none; the controller mirrors it (or not)
=====  ===========================  ======================================

Layouts: the Open Protocol specification as OpenProtocolInterpreter
(Rickedb, ``Communication/Mid000*.cs``) and node-open-protocol
(``src/mid/0002.js``, ``0004.js``) read it. They differ on 0004: node reads
only the 2-digit rev 1 code; OpenProtocolInterpreter widens it to 3 digits
from rev 2. Both are implemented, rev 1 the default.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import ClassVar

from shared.openprotocol.fields import Layout, LayoutMessage, Spec, numbered


class ErrorCode(enum.IntEnum):
    """0004 error codes (the specification's table; those the MIDs implemented here can get)."""

    NO_ERROR = 0
    INVALID_DATA = 1
    LAST_TIGHTENING_SUBSCRIPTION_EXISTS = 9  # 0060
    LAST_TIGHTENING_SUBSCRIPTION_MISSING = 10  # 0063
    ALARM_SUBSCRIPTION_EXISTS = 11  # 0070
    ALARM_SUBSCRIPTION_MISSING = 12  # 0073
    TIGHTENING_ID_NOT_FOUND = 15  # 0064
    CONNECTION_REJECTED_PROTOCOL_BUSY = 16  # 0001
    TOOL_INACCESSIBLE = 27  # 0040
    NOT_A_SYNC_MASTER = 30  # 0090, 0100: the controller is not a sync master/station controller
    MULTI_SPINDLE_STATUS_SUBSCRIPTION_EXISTS = 31  # 0090
    MULTI_SPINDLE_STATUS_SUBSCRIPTION_MISSING = 32  # 0093
    MULTI_SPINDLE_RESULT_SUBSCRIPTION_EXISTS = 33  # 0100
    MULTI_SPINDLE_RESULT_SUBSCRIPTION_MISSING = 34  # 0103
    TOOL_DOES_NOT_EXIST = 29  # 0040
    NO_ALARM_PRESENT = 58
    UNSUPPORTED_EXTRA_DATA_REVISION = 69  # 0008
    SUBSCRIPTION_EXISTS = 71  # 0008
    SUBSCRIPTION_MISSING = 72  # 0009
    SUBSCRIBED_MID_UNSUPPORTED = 73  # 0008
    SUBSCRIBED_MID_REVISION_UNSUPPORTED = 74  # 0008
    REQUESTED_MID_UNSUPPORTED = 75
    REQUESTED_MID_REVISION_UNSUPPORTED = 76
    COMMAND_FAILED = 79
    OPEN_PROTOCOL_COMMANDS_DISABLED = 92
    CLIENT_ALREADY_CONNECTED = 96  # 0001
    MID_REVISION_UNSUPPORTED = 97  # every MID
    CONTROLLER_INTERNAL_REQUEST_TIMEOUT = 98
    UNKNOWN_MID = 99


_NO_DATA: Layout = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class CommunicationStart(LayoutMessage):
    """0001: the integrator opens the session, asking 0002 at this revision."""

    MID: ClassVar[int] = 1
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: _NO_DATA, 2: _NO_DATA, 3: _NO_DATA}
    revision: int = 1


_ACK_1 = (
    Spec("cell_id", "cell id", 4),
    Spec("channel_id", "channel id", 2),
    Spec("controller_name", "controller name", 25, "text"),
)
_ACK_2 = (*_ACK_1, Spec("supplier_code", "supplier code", 3, "text"))
_ACK_3 = (
    *_ACK_2,
    Spec("open_protocol_version", "open protocol version", 19, "text"),
    Spec("controller_software_version", "controller software version", 19, "text"),
    Spec("tool_software_version", "tool software version", 19, "text"),
)


@dataclass(frozen=True, slots=True, kw_only=True)
class CommunicationStartAck(LayoutMessage):
    """0002: the controller accepts the session and says who it is."""

    MID: ClassVar[int] = 2
    LAYOUTS: ClassVar[dict[int, Layout]] = {
        1: numbered(*_ACK_1),
        2: numbered(*_ACK_2),
        3: numbered(*_ACK_3),
    }
    cell_id: int
    channel_id: int
    controller_name: str
    supplier_code: str | None = None  # rev 2
    open_protocol_version: str | None = None  # rev 3
    controller_software_version: str | None = None  # rev 3
    tool_software_version: str | None = None  # rev 3
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class CommunicationStop(LayoutMessage):
    """0003: the integrator closes the session."""

    MID: ClassVar[int] = 3
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: _NO_DATA}
    ANY_REVISION: ClassVar[bool] = True
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class CommandError(LayoutMessage):
    """0004: the controller refuses the message of MID ``mid`` with ``error_code``."""

    MID: ClassVar[int] = 4
    LAYOUTS: ClassVar[dict[int, Layout]] = {
        1: (Spec("mid", "mid", 4, low=1), Spec("error_code", "error code", 2)),
        2: (Spec("mid", "mid", 4, low=1), Spec("error_code", "error code", 3)),
    }
    mid: int
    error_code: int
    revision: int = 1

    @property
    def error_name(self) -> str:
        """The code's name in :class:`ErrorCode`, or ``"error <n>"`` for one not listed."""
        try:
            return ErrorCode(self.error_code).name
        except ValueError:
            return f"error {self.error_code}"


@dataclass(frozen=True, slots=True, kw_only=True)
class CommandAccepted(LayoutMessage):
    """0005: the message of MID ``mid`` was accepted (or, from the integrator, a 0900 received)."""

    MID: ClassVar[int] = 5
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: (Spec("mid", "mid", 4, low=1),)}
    mid: int
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class KeepAlive(LayoutMessage):
    """9999: sent by the integrator at least every 10 s; controllers may mirror it."""

    MID: ClassVar[int] = 9999
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: _NO_DATA}
    ANY_REVISION: ClassVar[bool] = True
    revision: int = 1
