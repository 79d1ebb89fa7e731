"""A station's batch of samples, filed as the samples it holds, each as if it had come alone.

An edge station sends its samples toward the line in batches
(:class:`~shared.messages.SampleBatch` on ``boltwatch/<st>/sample_batches``,
every 10 ms: :mod:`shared.sample_batching`). The MCAP files stay as they were
when each sample was a message of its own, so a Foxglove plot or a reader of
the files sees no difference: each sample is one :class:`Received` on
``boltwatch/<st>/samples`` with the ``boltwatch.Sample`` schema, its own JSON
as payload (:func:`shared.codec.encode`), ``publish_time`` its ``time_ns`` and
``sequence`` its ``sequence``.

``log_time`` is the time the recorder received it. A batch arrives at once,
so each sample's arrival is taken as the batch's arrival less how much older
the sample is than the batch's newest (at most :data:`MAX_SPREAD_NS`): samples
1 ms apart on the CAN bus are 1 ms apart in the file, as they were when each
came alone, and never earlier than the station's sample filed before them
(log times of a station's samples never go back).
"""

from __future__ import annotations

from services.recorder.live.incoming import Received
from shared import channels
from shared.codec import encode
from shared.messages import SampleBatch

SAMPLE = channels.SAMPLES.schema_name
#: the most a sample's log time is put before its batch's arrival: a batch spans 10 ms,
#: one gathered over a stall of the station's publisher at most a second of log time
MAX_SPREAD_NS = 1_000_000_000


class BatchSamples:
    """Turns each received batch into its samples, keeping each station's last log time."""

    def __init__(self) -> None:
        self._last_log_ns: dict[str, int] = {}
        self._keys: dict[str, str] = {}

    def samples(self, received: Received) -> list[Received]:
        """The samples of a batch :func:`~services.recorder.live.incoming.classify` took."""
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
        out: list[Received] = []
        for sample in samples:
            own_ns = sample.time_ns
            older_ns = min(max(newest_ns - own_ns, 0), MAX_SPREAD_NS)
            log_ns = floor_ns = max(arrival_ns - older_ns, floor_ns)
            out.append(Received(key, station, SAMPLE, sample, encode(sample), log_ns, own_ns))
        self._last_log_ns[station] = floor_ns
        return out
