"""What flows on a line, in one place: every channel of boltwatch and its contract.

A channel is a key below a station, ``boltwatch/<station>/<topic>``
(:mod:`shared.contract.keys`), carrying one message type of
:mod:`shared.contract.messages` as JSON with the schema the codec derives
(``boltwatch.<Type>``), put by one service (others that may put it in that
service's place: :attr:`Channel.also_by`) with one :class:`Qos`. Publishers
are declared from here; the recorder, ``boltwatch status``, the tests and the
benchmarks look channels up here (:func:`by_topic`, :func:`of_message`,
:data:`CHANNELS`). Adding a channel: its message type, its row below. The
table as a page: ``docs/reference/channels.md`` (written from this module);
why each channel is put as it is: ``docs/explanation/design.md``, "The line's
channels".

=================  ====================  ===========================================
topic              publisher             message, when
=================  ====================  ===========================================
``samples``        acquisition           :class:`Sample`, one per 1 kHz sample (placement
                   (openprotocol)        line: what the line's predictor decides on)
``sample_batches`` acquisition           :class:`SampleBatch`, every 50 ms (placement
                   (openprotocol)        edge: what the line records), with the
                                         events and intensities found in it
``tool``           acquisition           :class:`ToolState`, on every change
                   (openprotocol)
``bus``            acquisition           :class:`BusStats`, once a second
``events``         predictor             :class:`StickSlipEvent`, one per event (placement
                   (openprotocol)        edge: only when no batch is in progress)
``intensity``      predictor             :class:`Intensity`, one per event (the same)
                   (openprotocol)
``decision``       predictor             :class:`StopDecision`, at most one per run
                   (openprotocol)        (a bridge's: advisory, the controller stopped)
``stage``          predictor             :class:`StageDecision`, each command to a tool
                                         that runs a final stage (switch, pulse, finish)
``runs``           predictor             :class:`RunSummary`, one per run
                   (openprotocol)
``results``        predictor (import,    :class:`TighteningResult`, one per run, just
                   openprotocol)         before its summary: OK/NOK against the windows
``cycles``         predictor             :class:`CycleResult`, one per cycle of a
                   (openprotocol)        multi-spindle station, after its last spindle's
                                         summary: OK only when every spindle is
``predictor``      predictor             :class:`PredictorStats`, once a second
``recorder``       recorder              :class:`RecorderStats`, once a second
``wear/alert``     recorder              :class:`WearAlert`, when a tool is due
``wear/forecast``  recorder              :class:`WearForecast`, once per tool and horizon,
                                         when a tool is forecast due within it
``quality/alert``  recorder              :class:`QualityAlert`, when a program's Cpk or
                                         NOKs go out of bounds, and when back
``controller``     import (openprotocol) :class:`ControllerResult`, one per run
``tool_data``      openprotocol          :class:`ToolData`, when the controller says it
``alarms``         openprotocol          :class:`ControllerAlarm`, per alarm message
``openprotocol``   openprotocol          :class:`BridgeStats`, once a second
``spool``          acquisition           :class:`SpoolStats`, once a second: what the
                   (openprotocol)        station keeps until the line has it
``spool/ack``      recorder              :class:`SpoolAck`, once a second per spooling
                                         source: what it wrote to disk of the spool
``part``           plc (rig)             :class:`PartScan`, when a part arrives at the
                                         station: the runs that start after it tighten it
=================  ====================  ===========================================

In brackets: who else may put the channel (:attr:`Channel.also_by`). A
controller bridge (``boltwatch serve openprotocol``, publisher
``openprotocol``) stands for a CAN station's acquisition and predictor: it
publishes what they would, from what its controller says.

A part's id comes from the line, not from the tool: the line's PLC (or a
scanner at the station; publisher ``plc``, certificate ``<st>-plc``) puts it
when the part arrives, and the simulated rig stands in for it
(``[rig] bolts_per_part``). The station's predictor names the part in each
result (:attr:`TighteningResult.part_id`).

A station's samples go toward the line once, on one of the two sample
channels: one message per sample where a line predictor decides on them
(``[predictor] placement = "line"``), in batches otherwise (the decision is
taken on the station; the line only records them).

Not channels: ``health/<service>`` (liveliness tokens) and ``wear`` (the
recorder's queryable of the wear ledger), in :mod:`shared.contract.keys`.

Every channel is put with congestion control BLOCK: zenoh's default (DROP)
lost events under load, silently, and loss is counted end to end. Samples
and tool states share one priority, so a run's ``done`` never overtakes its
samples; a decision and a final stage's command are REAL_TIME. Samples, tool
states, decisions, a final stage's commands and part scans are express (no
batching in zenoh: latency counts; a part must reach the predictor before its
first run starts). Sample batches are not: they
are recorded, not decided on, and zenoh packs the batches of many stations
into one frame toward the line's recorder (``bench_line.py`` at 50 stations:
0.6 to 1.0 µs less of the recorder's CPU per sample, lag no worse).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Generic, TypeVar

from shared.contract import keys
from shared.contract.cycle_messages import CycleResult
from shared.contract.messages import (
    AlertAck,
    BridgeStats,
    BusStats,
    ControllerAlarm,
    ControllerResult,
    Intensity,
    PartScan,
    PredictorStats,
    QualityAlert,
    RecorderStats,
    RunSummary,
    Sample,
    SampleBatch,
    SpoolAck,
    SpoolStats,
    StageDecision,
    StickSlipEvent,
    StopDecision,
    TighteningResult,
    ToolData,
    ToolState,
    WearAlert,
    WearForecast,
)

MessageT = TypeVar("MessageT")

#: the encoding of every channel's payloads (MCAP's message encoding too)
ENCODING = "json"


@dataclass(frozen=True, slots=True)
class Qos:
    """How a channel is put, in zenoh's terms but no zenoh type: the contract needs no
    transport (:func:`shared.runtime.zenoh_session.declare_channel` turns it into options).

    Every channel is put with congestion control BLOCK (a put waits rather than drops:
    loss is counted end to end), at priority REAL_TIME where ``real_time`` is set and
    DATA otherwise; ``express`` puts go out at once, the others may be packed by zenoh
    into one frame with other puts."""

    real_time: bool = False  # zenoh's REAL_TIME priority; else DATA
    express: bool = False  # no batching: latency counts


@dataclass(frozen=True, slots=True)
class Channel(Generic[MessageT]):
    """One channel: the topic below its station, its message type, who puts it, how."""

    topic: str
    message_type: type[MessageT]
    #: the service that puts it (what the access control lets put it, per role)
    publisher: str
    qos: Qos = field(default_factory=Qos)
    #: who else may put it, in the place of ``publisher`` (a controller bridge, an import)
    also_by: tuple[str, ...] = ()
    #: the registry name of its message type (``boltwatch.<Type>``): MCAP schema names
    schema_name: str = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "schema_name", f"boltwatch.{self.message_type.__name__}")

    @property
    def publishers(self) -> tuple[str, ...]:
        """Every service that may put it: ``publisher`` first, then ``also_by``."""
        return (self.publisher, *self.also_by)

    def key(self, station: str) -> str:
        """``boltwatch/<station>/<topic>``."""
        return keys.station_key(station, self.topic)


#: what a controller bridge puts in the place of a CAN station's acquisition and predictor
_BRIDGE = ("openprotocol",)

SAMPLES = Channel("samples", Sample, "acquisition", Qos(express=True), _BRIDGE)
SAMPLE_BATCHES = Channel("sample_batches", SampleBatch, "acquisition", Qos(), _BRIDGE)
TOOL = Channel("tool", ToolState, "acquisition", Qos(express=True), _BRIDGE)
BUS = Channel("bus", BusStats, "acquisition")
EVENTS = Channel("events", StickSlipEvent, "predictor", also_by=_BRIDGE)
INTENSITY = Channel("intensity", Intensity, "predictor", also_by=_BRIDGE)
DECISION = Channel(
    "decision",
    StopDecision,
    "predictor",
    Qos(real_time=True, express=True),
    _BRIDGE,
)
STAGE = Channel("stage", StageDecision, "predictor", Qos(real_time=True, express=True))
RUNS = Channel("runs", RunSummary, "predictor", also_by=_BRIDGE)
RESULTS = Channel("results", TighteningResult, "predictor", also_by=("import", *_BRIDGE))
CYCLES = Channel("cycles", CycleResult, "predictor", also_by=_BRIDGE)
PREDICTOR = Channel("predictor", PredictorStats, "predictor")
RECORDER = Channel("recorder", RecorderStats, "recorder")
WEAR_ALERT = Channel("wear/alert", WearAlert, "recorder")
WEAR_FORECAST = Channel("wear/forecast", WearForecast, "recorder")
QUALITY_ALERT = Channel("quality/alert", QualityAlert, "recorder")
CONTROLLER = Channel("controller", ControllerResult, "import", also_by=_BRIDGE)
TOOL_DATA = Channel("tool_data", ToolData, "openprotocol")
ALARMS = Channel("alarms", ControllerAlarm, "openprotocol")
OPENPROTOCOL = Channel("openprotocol", BridgeStats, "openprotocol")
#: every spooling service's: a station's acquisition, its bridge, a line predictor
SPOOL = Channel("spool", SpoolStats, "acquisition", also_by=(*_BRIDGE, "predictor"))
SPOOL_ACK = Channel("spool/ack", SpoolAck, "recorder")
#: the line's PLC or the station's scanner; the simulated rig stands in for it
PART = Channel("part", PartScan, "plc", Qos(express=True), ("rig",))
#: the line's OPC UA server (``boltwatch serve opcua``): a condition's handling, recorded
ALERT_ACK = Channel("alert/ack", AlertAck, "opcua")

#: every channel, in the order of the table above
CHANNELS: tuple[Channel[Any], ...] = (
    SAMPLES,
    SAMPLE_BATCHES,
    TOOL,
    BUS,
    EVENTS,
    INTENSITY,
    DECISION,
    STAGE,
    RUNS,
    RESULTS,
    CYCLES,
    PREDICTOR,
    RECORDER,
    WEAR_ALERT,
    WEAR_FORECAST,
    QUALITY_ALERT,
    CONTROLLER,
    TOOL_DATA,
    ALARMS,
    OPENPROTOCOL,
    SPOOL,
    SPOOL_ACK,
    PART,
    ALERT_ACK,
)

_BY_TOPIC: dict[str, Channel[Any]] = {channel.topic: channel for channel in CHANNELS}
_BY_TYPE: dict[type, Channel[Any]] = {channel.message_type: channel for channel in CHANNELS}

#: registry name -> message type of every channel (MCAP schema names)
SCHEMA_TYPES: dict[str, type] = {channel.schema_name: channel.message_type for channel in CHANNELS}


def by_topic(topic: str) -> Channel[Any] | None:
    """The channel of a topic (the key below the station), None for any other key."""
    return _BY_TOPIC.get(topic)


def topics_of(publisher: str) -> tuple[str, ...]:
    """The topics ``publisher`` puts, or may put (:attr:`Channel.also_by`), in the order of
    :data:`CHANNELS`."""
    return tuple(channel.topic for channel in CHANNELS if publisher in channel.publishers)


def of_message(message: object) -> Channel[Any]:
    """The channel a message is put on (KeyError for a type no channel carries)."""
    return _BY_TYPE[type(message)]
