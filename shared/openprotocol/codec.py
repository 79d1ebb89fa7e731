"""Frames to messages and back: the registry of every MID this codec implements.

- :func:`decode` ``(frame) -> message``: by MID and revision; an MID not
  implemented gives :class:`UnknownMessage` (a value, not an exception); a
  revision not implemented or malformed content raises
  :class:`~shared.openprotocol.errors.OpenProtocolError` (``field ==
  "revision"`` for the former: a controller answers it with 0004 error 97).
- :func:`encode` ``(message) -> bytes``: the whole message on the wire (a NUL
  ends it, but for a message with binary data, 0900: the specification's
  2.2.4, "no NUL character is sent after the binary data").
- :data:`SUPPORTED_REVISIONS`: the revisions implemented per MID, lowest
  first, so an integrator can ask the highest and fall back, and a controller
  can refuse the others. :data:`ANY_REVISION_MIDS` are read and written at
  every revision (1-999) besides: messages with no data whose revision asks
  nothing of an answer (0003, 0062, 0063, 0072, 0073, 0075, 0077, 0092, 0093, 0102,
  0103, 9999). The
  specification gives them no data and no list of revisions ("For header
  description see section 2.2.2"), and integrators send them above 1:
  OpenProtocolInterpreter writes 0062 at revision 5 or 6 and 0063, 0072 and
  0073 at 2 (its ``TestMid00xx.cs``). A MID whose revision names the revision
  of its answer (0001, 0040, 0060, 0064, 0070) is read at the revisions
  implemented only (0090 and 0100 too): a controller answers another with 0004 error 97.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import ClassVar, Final, Protocol, Self

from shared.openprotocol.alarms import (
    Alarm,
    AlarmAcknowledge,
    AlarmAcknowledgedOnController,
    AlarmAcknowledgedOnControllerAck,
    AlarmStatus,
    AlarmStatusAck,
    AlarmSubscribe,
    AlarmUnsubscribe,
)
from shared.openprotocol.dialect import DEFAULT_DIALECT, Dialect
from shared.openprotocol.errors import OpenProtocolError
from shared.openprotocol.framing import BINARY_MIDS, Frame, HeaderFill, frame_bytes
from shared.openprotocol.multi_spindle import (
    MultiSpindleResult,
    MultiSpindleResultAcknowledge,
    MultiSpindleResultSubscribe,
    MultiSpindleResultUnsubscribe,
    MultiSpindleStatus,
    MultiSpindleStatusAcknowledge,
    MultiSpindleStatusSubscribe,
    MultiSpindleStatusUnsubscribe,
)
from shared.openprotocol.results import (
    LastTighteningResult,
    OldResultRequest,
    OldTighteningResult,
    ResultAcknowledge,
    ResultSubscribe,
    ResultUnsubscribe,
)
from shared.openprotocol.session import (
    CommandAccepted,
    CommandError,
    CommunicationStart,
    CommunicationStartAck,
    CommunicationStop,
    KeepAlive,
)
from shared.openprotocol.subscriptions import DataSubscribe, DataUnsubscribe
from shared.openprotocol.tool_data import ToolData, ToolDataRequest
from shared.openprotocol.traces import TraceCurve


class WireMessage(Protocol):
    """What every message class of this package offers the codec."""

    MID: ClassVar[int]

    @property
    def revision(self) -> int: ...

    @classmethod
    def revisions(cls) -> tuple[int, ...]: ...

    @classmethod
    def from_data(cls, data: bytes, revision: int, dialect: Dialect = ...) -> Self: ...

    def to_data(self, revision: int, dialect: Dialect = ...) -> bytes: ...


@dataclass(frozen=True, slots=True)
class UnknownMessage:
    """A frame of an MID this codec does not implement, kept whole."""

    frame: Frame

    @property
    def mid(self) -> int:
        return self.frame.mid


MESSAGE_TYPES: Final[Mapping[int, type[WireMessage]]] = {
    cls.MID: cls
    for cls in (
        CommunicationStart,
        CommunicationStartAck,
        CommunicationStop,
        CommandError,
        CommandAccepted,
        KeepAlive,
        DataSubscribe,
        DataUnsubscribe,
        ToolDataRequest,
        ToolData,
        ResultSubscribe,
        LastTighteningResult,
        ResultAcknowledge,
        ResultUnsubscribe,
        OldResultRequest,
        OldTighteningResult,
        AlarmSubscribe,
        Alarm,
        AlarmAcknowledge,
        AlarmUnsubscribe,
        AlarmAcknowledgedOnController,
        AlarmAcknowledgedOnControllerAck,
        AlarmStatus,
        AlarmStatusAck,
        MultiSpindleStatusSubscribe,
        MultiSpindleStatus,
        MultiSpindleStatusAcknowledge,
        MultiSpindleStatusUnsubscribe,
        MultiSpindleResultSubscribe,
        MultiSpindleResult,
        MultiSpindleResultAcknowledge,
        MultiSpindleResultUnsubscribe,
        TraceCurve,
    )
}
SUPPORTED_REVISIONS: Final[Mapping[int, tuple[int, ...]]] = {
    mid: cls.revisions() for mid, cls in sorted(MESSAGE_TYPES.items())
}
KNOWN_MIDS: Final = frozenset(SUPPORTED_REVISIONS)
ANY_REVISION_MIDS: Final = frozenset(
    mid for mid, cls in MESSAGE_TYPES.items() if getattr(cls, "ANY_REVISION", False)
)
#: the highest revision a header holds (three digits)
HIGHEST_REVISION: Final = 999


def implements(mid: int, revision: int) -> bool:
    """Whether the codec reads and writes ``mid`` at ``revision``."""
    if mid in ANY_REVISION_MIDS:
        return 1 <= revision <= HIGHEST_REVISION
    return revision in SUPPORTED_REVISIONS.get(mid, ())


def _check_revision(mid: int, revision: int) -> None:
    known = SUPPORTED_REVISIONS[mid]
    if not implements(mid, revision):
        why = f"revision {revision} is not implemented ({', '.join(map(str, known))})"
        raise OpenProtocolError(mid, "revision", why, revision=revision)


def decode(frame: Frame, *, dialect: Dialect = DEFAULT_DIALECT) -> WireMessage | UnknownMessage:
    """The message of ``frame``; :class:`UnknownMessage` for an MID not implemented."""
    cls = MESSAGE_TYPES.get(frame.mid)
    if cls is None:
        return UnknownMessage(frame)
    _check_revision(frame.mid, frame.revision)
    return cls.from_data(frame.data, frame.revision, dialect)


def encode(
    message: WireMessage | UnknownMessage,
    *,
    revision: int | None = None,
    fill: HeaderFill | None = None,
    dialect: Dialect = DEFAULT_DIALECT,
    no_ack: bool = False,
) -> bytes:
    """The wire bytes of ``message`` at ``revision`` (default: the message's own).

    ``fill`` overrides ``dialect.header_fill``; ``no_ack`` sets the header's
    no-ack flag (on a subscription: push without waiting for acknowledges).
    """
    fill = dialect.header_fill if fill is None else fill
    if isinstance(message, UnknownMessage):
        return frame_bytes(message.frame, fill=fill, terminator=dialect.nul_terminator)
    revision = message.revision if revision is None else revision
    _check_revision(message.MID, revision)
    data = message.to_data(revision, dialect)
    frame = Frame(mid=message.MID, revision=revision, no_ack=no_ack, data=data)
    # the specification (2.2.4): "no NUL character is sent after the binary data"
    terminator = dialect.nul_terminator and message.MID not in BINARY_MIDS
    return frame_bytes(frame, fill=fill, terminator=terminator)
