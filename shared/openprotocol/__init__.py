"""Atlas Copco Open Protocol, the pure protocol layer: bytes in, messages out.

No sockets here: the simulated controller (``services/rig``) and the bridge
(``boltwatch serve openprotocol``) both use it, each side encoding and
decoding.

- :mod:`.framing`: :class:`~.framing.Frame` (the 20-byte header and data),
  :func:`~.framing.frame_bytes`, :class:`~.framing.FrameReader` (frames out of a
  TCP stream: partial reads, garbage, bad lengths)
- :mod:`.codec`: :func:`~.codec.decode` / :func:`~.codec.encode` by MID and
  revision, :data:`~.codec.SUPPORTED_REVISIONS` (:func:`~.codec.implements`: and the
  MIDs read at any revision), :class:`~.codec.UnknownMessage`
- :mod:`.dialect`: what controllers differ on when writing (header fill, NUL
  terminator, 0900 byte order and separator) and the defaults
- :mod:`.errors`: :class:`~.errors.OpenProtocolError`, the one exception
- messages: :mod:`.session` (0001-0005, 9999), :mod:`.results` (0060-0065,
  layouts in :mod:`.result_layouts`), :mod:`.subscriptions` (0008/0009, 0900
  subscription data), :mod:`.traces` (0900), :mod:`.tool_data` (0040/0041),
  :mod:`.alarms` (0070-0077), :mod:`.multi_spindle` (0090-0093, 0100-0103: a
  multi-spindle system's status and result of each synchronised cycle)
- :mod:`.fields` (fixed-width field layouts, read and written),
  :mod:`.timestamps` (controller time text <-> ns since the epoch)
"""

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
from shared.openprotocol.codec import (
    ANY_REVISION_MIDS,
    HIGHEST_REVISION,
    KNOWN_MIDS,
    SUPPORTED_REVISIONS,
    UnknownMessage,
    WireMessage,
    decode,
    encode,
    implements,
)
from shared.openprotocol.dialect import DEFAULT_DIALECT, Dialect
from shared.openprotocol.errors import OpenProtocolError
from shared.openprotocol.framing import BINARY_MIDS, Frame, FrameReader, frame_bytes
from shared.openprotocol.multi_spindle import (
    MultiSpindleResult,
    MultiSpindleResultAcknowledge,
    MultiSpindleResultSubscribe,
    MultiSpindleResultUnsubscribe,
    MultiSpindleStatus,
    MultiSpindleStatusAcknowledge,
    MultiSpindleStatusSubscribe,
    MultiSpindleStatusUnsubscribe,
    SpindleResult,
    SpindleStatus,
)
from shared.openprotocol.results import (
    BatchStatus,
    LastTighteningResult,
    OldResultRequest,
    OldTighteningResult,
    ResultAcknowledge,
    ResultSubscribe,
    ResultUnsubscribe,
    ValueStatus,
)
from shared.openprotocol.session import (
    CommandAccepted,
    CommandError,
    CommunicationStart,
    CommunicationStartAck,
    CommunicationStop,
    ErrorCode,
    KeepAlive,
)
from shared.openprotocol.subscriptions import (
    DataSubscribe,
    DataUnsubscribe,
    trace_extra_data,
    trace_types_of,
)
from shared.openprotocol.timestamps import format_timestamp, timestamp_ns
from shared.openprotocol.tool_data import ToolData, ToolDataRequest
from shared.openprotocol.traces import (
    UNIT_DEGREE,
    UNIT_NM,
    ResolutionField,
    TraceCurve,
    TraceType,
    VariableField,
)

__all__ = [
    "ANY_REVISION_MIDS",
    "BINARY_MIDS",
    "DEFAULT_DIALECT",
    "HIGHEST_REVISION",
    "KNOWN_MIDS",
    "SUPPORTED_REVISIONS",
    "UNIT_DEGREE",
    "UNIT_NM",
    "Alarm",
    "AlarmAcknowledge",
    "AlarmAcknowledgedOnController",
    "AlarmAcknowledgedOnControllerAck",
    "AlarmStatus",
    "AlarmStatusAck",
    "AlarmSubscribe",
    "AlarmUnsubscribe",
    "BatchStatus",
    "CommandAccepted",
    "CommandError",
    "CommunicationStart",
    "CommunicationStartAck",
    "CommunicationStop",
    "DataSubscribe",
    "DataUnsubscribe",
    "Dialect",
    "ErrorCode",
    "Frame",
    "FrameReader",
    "KeepAlive",
    "LastTighteningResult",
    "MultiSpindleResult",
    "MultiSpindleResultAcknowledge",
    "MultiSpindleResultSubscribe",
    "MultiSpindleResultUnsubscribe",
    "MultiSpindleStatus",
    "MultiSpindleStatusAcknowledge",
    "MultiSpindleStatusSubscribe",
    "MultiSpindleStatusUnsubscribe",
    "OldResultRequest",
    "OldTighteningResult",
    "OpenProtocolError",
    "ResolutionField",
    "ResultAcknowledge",
    "ResultSubscribe",
    "ResultUnsubscribe",
    "SpindleResult",
    "SpindleStatus",
    "ToolData",
    "ToolDataRequest",
    "TraceCurve",
    "TraceType",
    "UnknownMessage",
    "ValueStatus",
    "VariableField",
    "WireMessage",
    "decode",
    "encode",
    "format_timestamp",
    "frame_bytes",
    "implements",
    "timestamp_ns",
    "trace_extra_data",
    "trace_types_of",
]
