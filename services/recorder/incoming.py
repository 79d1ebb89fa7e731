"""What the recorder receives: one zenoh sample, classified and (when it is ours) decoded.

A key ``boltwatch/<station>/<topic>`` whose topic names a message type (see
:data:`TOPIC_TYPES`) is decoded with :mod:`shared.codec` (the checking
:func:`~shared.codec.decoder` for flat types: samples at 1 kHz per station
are most of what a line's recorder does); anything else is kept as raw
bytes. Nothing is dropped here: a payload that does not decode (bad JSON, or
a field of the wrong type) is marked ``decodable=False`` and still recorded
(on a raw channel).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from services.recorder.wear_watch import ALERT_TOPIC, WearAlert
from shared import keys
from shared.codec import decode, decoder
from shared.errors import InputError
from shared.messages import MESSAGE_TYPES

#: Registry name -> message type of everything recorded schema'd: the shared
#: messages and the recorder's own wear alert.
RECORDED_TYPES: dict[str, type] = {**MESSAGE_TYPES, "boltwatch.WearAlert": WearAlert}

#: zenoh topic (key below the station) -> registry name of its message type
TOPIC_TYPES: dict[str, str] = {
    keys.SAMPLES: "boltwatch.Sample",
    keys.TOOL: "boltwatch.ToolState",
    keys.BUS: "boltwatch.BusStats",
    keys.EVENTS: "boltwatch.StickSlipEvent",
    keys.INTENSITY: "boltwatch.Intensity",
    keys.DECISION: "boltwatch.StopDecision",
    keys.RUNS: "boltwatch.RunSummary",
    keys.RECORDER: "boltwatch.RecorderStats",
    keys.CONTROLLER: "boltwatch.ControllerResult",
    ALERT_TOPIC: "boltwatch.WearAlert",
}


def _decoder_of(message_type: type) -> Callable[[bytes], Any]:
    try:
        return decoder(message_type)
    except TypeError:  # nested dataclasses or lists: the general decoder
        return lambda payload: decode(message_type, payload)


#: zenoh topic -> (registry name, decoder) of its message type
_TOPIC_DECODERS: dict[str, tuple[str, Callable[[bytes], Any]]] = {
    topic: (name, _decoder_of(RECORDED_TYPES[name])) for topic, name in TOPIC_TYPES.items()
}

#: Station folder of keys outside ``boltwatch/<station>/...``.
OTHER_STATION = "_other"


@dataclass(frozen=True, slots=True)
class Received:
    """One received payload with what the recorder needs to file it."""

    key: str
    station: str
    schema_name: str | None  # registry name; None: not a boltwatch message key
    message: Any  # the decoded dataclass, None when raw or undecodable
    payload: bytes
    log_time_ns: int  # receive time in the recorder
    publish_time_ns: int  # the message's own time (acquisition/decision), else log_time_ns

    @property
    def decodable(self) -> bool:
        return self.schema_name is None or self.message is not None

    @property
    def run_id(self) -> int | None:
        return getattr(self.message, "run_id", None)

    @property
    def sequence(self) -> int | None:
        """Sample.sequence for samples; None for every other message."""
        if self.schema_name == "boltwatch.Sample" and self.message is not None:
            return int(self.message.sequence)
        return None

    @property
    def run_started(self) -> bool:
        """True for ToolState(state="running"), the start of a run."""
        return (
            self.schema_name == "boltwatch.ToolState"
            and getattr(self.message, "state", None) == "running"
        )


def classify(key: str, payload: bytes, log_time_ns: int) -> Received:
    """Decode ``payload`` received on ``key`` when the key names a boltwatch message."""
    try:
        station, topic = keys.split_key(key)
    except ValueError:
        return Received(key, OTHER_STATION, None, None, payload, log_time_ns, log_time_ns)
    known = _TOPIC_DECODERS.get(topic)
    if known is None:
        return Received(key, station, None, None, payload, log_time_ns, log_time_ns)
    schema_name, decode_payload = known
    try:
        message: Any = decode_payload(payload)
    except InputError:
        return Received(key, station, schema_name, None, payload, log_time_ns, log_time_ns)
    # RunSummary has no time_ns: it is published when the run ended.
    own_time = getattr(message, "time_ns", getattr(message, "ended_ns", None))
    publish_time_ns = own_time if isinstance(own_time, int) else log_time_ns
    return Received(key, station, schema_name, message, payload, log_time_ns, publish_time_ns)
