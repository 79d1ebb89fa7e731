"""What the recorder receives: one zenoh sample, classified and (when it is ours) decoded.

A key ``boltwatch/<station>/<topic>`` whose topic is a channel
(:mod:`shared.contract.channels`) is decoded with :mod:`shared.contract.codec`; anything else
is kept as raw bytes. A :class:`~shared.contract.messages.SampleBatch` is checked
sample by sample as samples that came alone are (:mod:`.sample_batches` then
files each sample as if it had). Nothing is dropped here: a payload that is refused is marked
``decodable=False`` (with the reason in ``problem``) and still recorded, byte
for byte, on its key's raw channel, with its arrival as its publish time.
Refused are payloads the decoder refuses (bad JSON, too large or nested too
deeply, a wrong type, a value out of its bounds: :mod:`shared.contract.message_fields`),
a message naming another station than its key's (a wear ledger must not
count it elsewhere), a message whose own time is negative or more than
:data:`MAX_AHEAD_S` ahead of its arrival (no clock on the line is that far
ahead: it would be a publish time no MCAP reader should see, and a sample's
lag), and a sample whose
torque, angle or force is outside its station's sensor range (not a
measurement; the predictor's core drops it too). A message may be old (a
controller's result fetched after the run, a replay): a time before its
arrival is kept. A key whose station is not a station id (``[A-Za-z0-9_-]``,
at most 64) is filed under :data:`OTHER_STATION`, raw.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any, NamedTuple

from shared.contract import channels, keys
from shared.contract import decoder
from shared.contract import STATION_ID
from shared.contract import Intensity, Sample, SampleBatch, StickSlipEvent
from shared.contract import CONTRACT_RANGE, SensorRange
from shared.errors import InputError

#: how far ahead of its arrival a message's own time may be: the clocks of two hosts of
#: a line differ by milliseconds with NTP; five minutes is a clock gone wrong or a forgery
MAX_AHEAD_S = 300
_MAX_AHEAD_NS = MAX_AHEAD_S * 1_000_000_000

#: zenoh topic -> (registry name, decoder) of its message type: every channel
_TOPIC_DECODERS: dict[str, tuple[str, Callable[[bytes], Any]]] = {
    channel.topic: (channel.schema_name, decoder(channel.message_type))
    for channel in channels.CHANNELS
}

#: Station folder of keys outside ``boltwatch/<station>/...``.
OTHER_STATION = "_other"


class Received(NamedTuple):
    """One received payload with what the recorder needs to file it.

    A named tuple rather than a frozen dataclass: built for every message a
    line sends, and a frozen dataclass's ``__init__`` costs three times as much.
    """

    key: str
    station: str
    schema_name: str | None  # registry name; None: not a boltwatch message key
    message: Any  # the decoded dataclass, None when raw or undecodable
    payload: bytes
    log_time_ns: int  # receive time in the recorder
    publish_time_ns: int  # the message's own time (acquisition/decision), else log_time_ns
    problem: str | None = None  # why a payload on a message key was refused

    @property
    def decodable(self) -> bool:
        return self.schema_name is None or self.message is not None

    @property
    def run_id(self) -> int | None:
        return getattr(self.message, "run_id", None)

    @property
    def sequence(self) -> int | None:
        """Sample.sequence for samples; None for every other message."""
        if self.schema_name == channels.SAMPLES.schema_name and self.message is not None:
            return int(self.message.sequence)
        return None

    @property
    def run_started(self) -> bool:
        """True for ToolState(state="running"), the start of a run."""
        return (
            self.schema_name == channels.TOOL.schema_name
            and getattr(self.message, "state", None) == "running"
        )


def classify(
    key: str,
    payload: bytes,
    log_time_ns: int,
    sensor_ranges: Mapping[str, SensorRange] | None = None,
) -> Received:
    """Decode ``payload`` received on ``key`` when the key names a boltwatch message.

    ``sensor_ranges``: each station's sensor range (others: the contract's).
    """
    try:
        station, topic = keys.split_key(key)
    except ValueError:
        return Received(key, OTHER_STATION, None, None, payload, log_time_ns, log_time_ns)
    if station not in _STATIONS_SEEN:
        if STATION_ID.fullmatch(station) is None:
            return Received(key, OTHER_STATION, None, None, payload, log_time_ns, log_time_ns)
        if len(_STATIONS_SEEN) < _STATIONS_KEPT:
            _STATIONS_SEEN.add(station)
    known = _TOPIC_DECODERS.get(topic)
    if known is None:
        return Received(key, station, None, None, payload, log_time_ns, log_time_ns)
    schema_name, decode_payload = known
    try:
        message: Any = decode_payload(payload)
        if message.station != station:
            raise InputError(f"it names station {message.station!r}, on a key of {station!r}")
        own_time = getattr(message, "time_ns", None)
        if own_time is None:  # RunSummary has no time_ns: it is published when the run ended
            own_time = getattr(message, "ended_ns", None)
        if type(own_time) is not int:
            own_time = log_time_ns
        elif not 0 <= own_time <= log_time_ns + _MAX_AHEAD_NS:
            raise InputError(_time_problem(own_time, log_time_ns))
        if schema_name == _SAMPLE:
            sensors = CONTRACT_RANGE if sensor_ranges is None else sensor_ranges.get(station)
            _check_measured(message, sensors or CONTRACT_RANGE)
        elif schema_name == _BATCH:
            sensors = CONTRACT_RANGE if sensor_ranges is None else sensor_ranges.get(station)
            _check_batch(message, log_time_ns, sensors or CONTRACT_RANGE)
    except InputError as err:
        return Received(
            key, station, schema_name, None, payload, log_time_ns, log_time_ns, str(err)
        )
    return Received(key, station, schema_name, message, payload, log_time_ns, own_time)


#: station chunks of keys already found to be station ids (a handful on a line)
_STATIONS_SEEN: set[str] = set()
_STATIONS_KEPT = 1024


def _time_problem(own_time_ns: int, arrival_ns: int) -> str:
    if own_time_ns < 0:
        return f"its time {own_time_ns} ns is before 1970"
    ahead_s = (own_time_ns - arrival_ns) / 1e9
    return f"its time is {ahead_s:.0f} s ahead of its arrival (at most {MAX_AHEAD_S} s)"


_SAMPLE = channels.SAMPLES.schema_name
_BATCH = channels.SAMPLE_BATCHES.schema_name


def _check_batch(batch: SampleBatch, arrival_ns: int, sensors: SensorRange) -> None:
    """Each sample, event and intensity of a batch as :func:`classify` checks one that came
    alone: one bad one refuses the batch (recorded raw, byte for byte, on its own channel)."""
    parts: tuple[tuple[str, Sequence[Sample | StickSlipEvent | Intensity]], ...] = (
        ("samples", batch.samples),
        ("events", batch.events),
        ("intensities", batch.intensities),
    )
    latest_ns = arrival_ns + _MAX_AHEAD_NS
    for name, messages in parts:
        for index, message in enumerate(messages):
            try:
                if message.station != batch.station:
                    raise InputError(f"it names station {message.station!r}, in a batch of its own")
                if not 0 <= message.time_ns <= latest_ns:
                    raise InputError(_time_problem(message.time_ns, arrival_ns))
                if type(message) is Sample:
                    _check_measured(message, sensors)
            except InputError as err:
                raise InputError(f"{name}[{index}]: {err}") from None


def _check_measured(sample: Sample, sensors: SensorRange) -> None:
    """A sample's values must be what the station's sensors can measure."""
    torque_low, torque_high = sensors.torque_nm
    angle_low, angle_high = sensors.angle_deg
    force_low, force_high = sensors.force_n
    force = sample.force_n
    if (
        torque_low <= sample.torque_nm <= torque_high
        and angle_low <= sample.angle_deg <= angle_high
        and (force is None or force_low <= force <= force_high)
    ):
        return
    low, high = sensors.torque_nm
    if not low <= sample.torque_nm <= high:
        raise InputError(f"torque_nm {sample.torque_nm} is outside the sensor's {low} to {high}")
    low, high = sensors.angle_deg
    if not low <= sample.angle_deg <= high:
        raise InputError(f"angle_deg {sample.angle_deg} is outside the sensor's {low} to {high}")
    low, high = sensors.force_n
    if force is not None and not low <= force <= high:
        raise InputError(f"force_n {force} is outside the sensor's {low} to {high}")
