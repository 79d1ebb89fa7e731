"""A station's batch of samples, filed as the samples it holds, each as if it had come alone.

An edge station sends its samples toward the line in batches
(:class:`~shared.contract.messages.SampleBatch` on ``boltwatch/<st>/sample_batches``,
:mod:`shared.runtime.sample_batching`). The MCAP files stay as they were when each
sample was a message of its own, so a Foxglove plot or a reader of the files
sees no difference: each sample is one :class:`Received` on
``boltwatch/<st>/samples`` with the ``boltwatch.Sample`` schema, its own JSON
as payload, ``publish_time`` its ``time_ns`` and ``sequence`` its ``sequence``.
The JSON is the station's own, cut out of the batch's payload when the batch
is in the form the station's publisher writes (:func:`sample_texts`; a sample
that came alone is recorded byte for byte too), and encoded again
(:func:`shared.contract.codec.encode`) otherwise.

``log_time`` is the time the recorder received it. A batch arrives at once,
so each sample's arrival is taken as the batch's arrival less how much older
the sample is than the batch's newest (at most :data:`MAX_SPREAD_NS`): samples
1 ms apart on the CAN bus are 1 ms apart in the file, as they were when each
came alone, and never earlier than the station's sample filed before them
(log times of a station's samples never go back).

The events and intensities a batch carries are filed after its samples, each
on its own channel as if it had come alone, with the batch's arrival as log
time (:meth:`BatchSamples.found`; encoded again, as the station encoded them).
"""

from __future__ import annotations

from shared.contract import SampleBatch, channels, encode
from shared.recordings import Received

SAMPLE = channels.SAMPLES.schema_name
EVENTS, INTENSITY = channels.EVENTS, channels.INTENSITY
#: the most a sample's log time is put before its batch's arrival: a batch spans 50 ms,
#: one gathered over a stall of the station's publisher at most a second of log time
MAX_SPREAD_NS = 1_000_000_000


class BatchSamples:
    """Turns each received batch into its samples, keeping each station's last log time."""

    def __init__(self) -> None:
        self._last_log_ns: dict[str, int] = {}
        self._keys: dict[str, str] = {}

    def samples(self, received: Received) -> list[Received]:
        """The samples of a batch :func:`~shared.recordings.received.classify` took."""
        batch: SampleBatch = received.message
        samples = batch.samples
        if not samples:
            return []
        station = received.station
        key = self._keys.get(station)
        if key is None:
            key = self._keys[station] = channels.SAMPLES.key(station)
        arrival_ns = received.log_time_ns
        newest_ns = samples[-1].time_ns
        floor_ns = self._last_log_ns.get(station, 0)
        texts = sample_texts(received.payload, batch) or [encode(sample) for sample in samples]
        out: list[Received] = []
        for sample, text in zip(samples, texts, strict=True):
            own_ns = sample.time_ns
            older_ns = min(max(newest_ns - own_ns, 0), MAX_SPREAD_NS)
            log_ns = floor_ns = max(arrival_ns - older_ns, floor_ns)
            out.append(Received(key, station, SAMPLE, sample, text, log_ns, own_ns))
        self._last_log_ns[station] = floor_ns
        return out

    def found(self, received: Received) -> list[Received]:
        """The events of a batch, then their intensities, each on its own channel with the
        batch's arrival as log time (after every sample of the batch)."""
        batch: SampleBatch = received.message
        station, arrival_ns = received.station, received.log_time_ns
        return [
            Received(channel.key(station), station, channel.schema_name, message, encode(message),
                     arrival_ns, message.time_ns)
            for channel, messages in ((EVENTS, batch.events), (INTENSITY, batch.intensities))
            for message in messages
        ]  # fmt: skip


def sample_texts(payload: bytes, batch: SampleBatch) -> list[bytes] | None:
    """The JSON of each sample of ``batch`` as it stands in ``payload``, the batch's JSON, when
    that is ``{"station":..,"time_ns":..,"samples":[{..},..,{..}]`` then ``}`` or the events
    and intensities, written compact (as :func:`shared.contract.codec.encode` writes it); None
    otherwise.

    Exact because ``batch`` decoded from ``payload``: a sample is a flat object
    (no arrays, no nested objects) whose only string is its station id, which
    holds no brace and no bracket, so ``},{`` occurs only between two samples and
    the first ``]`` after the prefix closes the list; what follows holds no second
    ``samples`` key (nor an escape that could spell one).
    """
    prefix = b'{"station":"%s","time_ns":%d,"samples":[{' % (batch.station.encode(), batch.time_ns)
    if not payload.startswith(prefix):
        return None
    end = payload.find(b"]", len(prefix))
    tail = payload[end + 1 :]
    if (
        end < 0
        or payload[end - 1 : end] != b"}"
        or not (tail == b"}" or tail.startswith(b',"events":['))
        or b'"samples"' in tail
        or b"\\" in tail
    ):
        return None
    texts = payload[len(prefix) : end - 1].split(b"},{")
    if len(texts) != len(batch.samples):
        return None
    return [b"{" + text + b"}" for text in texts]
