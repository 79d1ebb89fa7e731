"""What flows on a line, in one place: every channel of boltwatch and its contract.

A channel is a key below a station, ``boltwatch/<station>/<topic>``
(:mod:`shared.keys`), carrying one message type of :mod:`shared.messages`,
encoded as JSON by :mod:`shared.codec` with the JSON schema the codec
derives (the MCAP channel's schema, named ``boltwatch.<Type>``), put by one
service with one set of zenoh options (priority, congestion control,
express). Publishers are declared from here (:meth:`Channel.declare_publisher`);
the recorder, ``boltwatch status``, the tests and the benchmarks look channels
up here (:func:`by_topic`, :func:`of_message`, :data:`CHANNELS`). Adding a
channel: its message type in :mod:`shared.messages`, its row below.

=================  ====================  ===========================================
topic              publisher             message, when
=================  ====================  ===========================================
``samples``        acquisition           :class:`Sample`, one per 1 kHz sample (placement
                                         line: what the line's predictor decides on)
``sample_batches`` acquisition           :class:`SampleBatch`, every 10 ms (placement
                                         edge: what the line records)
``tool``           acquisition           :class:`ToolState`, on every change
``bus``            acquisition           :class:`BusStats`, once a second
``events``         predictor             :class:`StickSlipEvent`, one per event
``intensity``      predictor             :class:`Intensity`, one per event
``decision``       predictor             :class:`StopDecision`, at most one per run
``runs``           predictor             :class:`RunSummary`, one per run
``results``        predictor (import,    :class:`TighteningResult`, one per run, just
                   a bridge)             before its summary: OK/NOK against the windows
``predictor``      predictor             :class:`PredictorStats`, once a second
``recorder``       recorder              :class:`RecorderStats`, once a second
``wear/alert``     recorder              :class:`WearAlert`, when a tool is due
``controller``     import (a bridge)     :class:`ControllerResult`, one per run
=================  ====================  ===========================================

A station's samples go toward the line once, on one of the two sample
channels: one message per sample where a line predictor decides on them
(``[predictor] placement = "line"``), in batches otherwise (the decision is
taken on the station; the line only records them).

Not channels: ``health/<service>`` (liveliness tokens) and ``wear`` (the
recorder's queryable of the wear ledger), in :mod:`shared.keys`.

Every channel is put with congestion control BLOCK: zenoh's default (DROP)
lost events under load, silently, and loss is counted end to end. Samples
and tool states share one priority, so a run's ``done`` never overtakes its
samples; a decision is REAL_TIME. Samples, tool states and decisions are
express (no batching in zenoh: latency counts).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Generic, TypeVar

import zenoh

from shared import keys
from shared.messages import (
    BusStats,
    ControllerResult,
    Intensity,
    PredictorStats,
    RecorderStats,
    RunSummary,
    Sample,
    SampleBatch,
    StickSlipEvent,
    StopDecision,
    TighteningResult,
    ToolState,
    WearAlert,
)

MessageT = TypeVar("MessageT")

#: the encoding of every channel's payloads (MCAP's message encoding too)
ENCODING = "json"


@dataclass(frozen=True, slots=True)
class Qos:
    """How a channel is put (zenoh's options)."""

    priority: zenoh.Priority = field(default_factory=lambda: zenoh.Priority.DATA)
    express: bool = False  # no batching: latency counts
    congestion_control: zenoh.CongestionControl = field(
        default_factory=lambda: zenoh.CongestionControl.BLOCK
    )

    def options(self) -> dict[str, Any]:
        """Keyword arguments of ``declare_publisher`` and ``put``."""
        return {
            "priority": self.priority,
            "express": self.express,
            "congestion_control": self.congestion_control,
        }


@dataclass(frozen=True, slots=True)
class Channel(Generic[MessageT]):
    """One channel: the topic below its station, its message type, who puts it, how."""

    topic: str
    message_type: type[MessageT]
    publisher: str
    qos: Qos = field(default_factory=Qos)
    #: the registry name of its message type (``boltwatch.<Type>``): MCAP schema names
    schema_name: str = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "schema_name", f"boltwatch.{self.message_type.__name__}")

    def key(self, station: str) -> str:
        """``boltwatch/<station>/<topic>``."""
        return keys.station_key(station, self.topic)

    def declare_publisher(self, session: zenoh.Session, station: str) -> zenoh.Publisher:
        """A publisher of this channel for ``station``, with the channel's options."""
        return session.declare_publisher(self.key(station), **self.qos.options())


SAMPLES = Channel("samples", Sample, "acquisition", Qos(express=True))
SAMPLE_BATCHES = Channel("sample_batches", SampleBatch, "acquisition", Qos(express=True))
TOOL = Channel("tool", ToolState, "acquisition", Qos(express=True))
BUS = Channel("bus", BusStats, "acquisition")
EVENTS = Channel("events", StickSlipEvent, "predictor")
INTENSITY = Channel("intensity", Intensity, "predictor")
DECISION = Channel(
    "decision", StopDecision, "predictor", Qos(priority=zenoh.Priority.REAL_TIME, express=True)
)
RUNS = Channel("runs", RunSummary, "predictor")
RESULTS = Channel("results", TighteningResult, "predictor")
PREDICTOR = Channel("predictor", PredictorStats, "predictor")
RECORDER = Channel("recorder", RecorderStats, "recorder")
WEAR_ALERT = Channel("wear/alert", WearAlert, "recorder")
CONTROLLER = Channel("controller", ControllerResult, "import")

#: every channel, in the order of the table above
CHANNELS: tuple[Channel[Any], ...] = (
    SAMPLES,
    SAMPLE_BATCHES,
    TOOL,
    BUS,
    EVENTS,
    INTENSITY,
    DECISION,
    RUNS,
    RESULTS,
    PREDICTOR,
    RECORDER,
    WEAR_ALERT,
    CONTROLLER,
)

_BY_TOPIC: dict[str, Channel[Any]] = {channel.topic: channel for channel in CHANNELS}
_BY_TYPE: dict[type, Channel[Any]] = {channel.message_type: channel for channel in CHANNELS}

#: registry name -> message type of every channel (MCAP schema names)
SCHEMA_TYPES: dict[str, type] = {channel.schema_name: channel.message_type for channel in CHANNELS}


def by_topic(topic: str) -> Channel[Any] | None:
    """The channel of a topic (the key below the station), None for any other key."""
    return _BY_TOPIC.get(topic)


def topics_of(publisher: str) -> tuple[str, ...]:
    """The topics ``publisher`` puts, in the order of :data:`CHANNELS`."""
    return tuple(channel.topic for channel in CHANNELS if channel.publisher == publisher)


def of_message(message: object) -> Channel[Any]:
    """The channel a message is put on (KeyError for a type no channel carries)."""
    return _BY_TYPE[type(message)]
