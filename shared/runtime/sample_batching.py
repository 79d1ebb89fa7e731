"""Samples toward the line in batches: the batch in progress on a station's publisher thread.

An edge station decides on its own box (the predictor runs on the
acquisition's CAN thread), so the line needs its samples only to record
them: one zenoh message per sample would cost the router and the recorder a
message's price a thousand times a second per station. The station's
:class:`~shared.runtime.queued_publisher.QueuedPublisher` therefore gathers its
samples into a :class:`~shared.contract.messages.SampleBatch` and publishes it on
:data:`shared.contract.channels.SAMPLE_BATCHES` when the oldest sample in it is
:data:`BATCH_PERIOD_S` old, when it holds :data:`MAX_BATCH_SAMPLES`, when a
sample of another run comes, and before anything else the station publishes
(a run's ``done``, its bus counters, the predictor's decisions), so the order
of everything a station publishes is kept: a batch never overtakes the tool
state before it. The stick-slip events the predictor finds, and their
intensities, go into the batch in progress, after the samples they were found
in (:meth:`SampleBatching.add_found`): at 40 events a second a station would
otherwise send a batch, an event and an intensity for each, three messages
where one does. An event with no batch of its run in progress (the batch was
just sent) goes alone, after it: never before its samples either way.

Clock: ``now_s`` is :func:`time.monotonic` of the publisher thread.
"""

from __future__ import annotations

import time

from shared.contract import Intensity, Sample, SampleBatch, StickSlipEvent

#: the longest a sample waits for its batch, seconds (20 batches a second at 1 kHz): each
#: message costs the line's router and recorder about as much as 5 samples in a batch do,
#: and 50 ms is still live to a person watching (bench_line.py, 50 stations: 10 ms 12.4 µs
#: of recorder CPU a sample, 25 ms 10.2, 50 ms 9.4)
BATCH_PERIOD_S = 0.050
#: the most samples in one batch (a burst after a stall); about 7 KB, far below 64 KiB
MAX_BATCH_SAMPLES = 50


class SampleBatching:
    """The samples of one station waiting for their batch, oldest first."""

    def __init__(
        self,
        station: str,
        period_s: float = BATCH_PERIOD_S,
        max_samples: int = MAX_BATCH_SAMPLES,
    ) -> None:
        self._station = station
        self._period_s = period_s
        self._max_samples = max_samples
        self._samples: list[Sample] = []
        self._events: list[StickSlipEvent] = []
        self._intensities: list[Intensity] = []
        self._due_s = 0.0  # when the batch in progress must go (monotonic seconds)

    def add(self, sample: Sample, now_s: float) -> list[SampleBatch]:
        """Append ``sample``; the batches that are ready now (none, one, or two when a new
        run starts in a batch that is also due), oldest first."""
        ready: list[SampleBatch] = []
        samples = self._samples
        if samples and samples[-1].run_id != sample.run_id:
            ready.append(self._take())
            samples = self._samples
        if not samples:
            self._due_s = now_s + self._period_s
        samples.append(sample)
        if len(samples) >= self._max_samples or now_s >= self._due_s:
            ready.append(self._take())
        return ready

    def add_found(self, message: StickSlipEvent | Intensity) -> bool:
        """Put an event or its intensity into the batch in progress, after its samples; False
        when no batch of its run is in progress (it goes alone)."""
        samples = self._samples
        if not samples or samples[-1].run_id != message.run_id:
            return False
        if isinstance(message, StickSlipEvent):
            self._events.append(message)
        else:
            self._intensities.append(message)
        return True

    def take(self) -> SampleBatch | None:
        """The batch in progress (None when no sample waits); the next one starts empty."""
        return self._take() if self._samples else None

    def wait_s(self, now_s: float) -> float | None:
        """Seconds until the batch in progress is due (0 when overdue); None when empty."""
        if not self._samples:
            return None
        return max(0.0, self._due_s - now_s)

    def _take(self) -> SampleBatch:
        batch = SampleBatch(
            self._station, time.time_ns(), self._samples, self._events, self._intensities
        )
        self._samples, self._events, self._intensities = [], [], []
        return batch
