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
just sent) goes alone, after it: never before its samples either way. A
multi-spindle station's spindles run at once, their samples interleaved: each
run has a batch of its own in progress (at most one per spindle), so a batch
still holds one run and is as full as a single spindle's.

Clock: ``now_s`` is :func:`time.monotonic` of the publisher thread.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from shared.contract import Intensity, Sample, SampleBatch, StickSlipEvent

#: the longest a sample waits for its batch, seconds (20 batches a second at 1 kHz): each
#: message costs the line's router and recorder about as much as 5 samples in a batch do,
#: and 50 ms is still live to a person watching (bench_line.py, 50 stations: 10 ms 12.4 µs
#: of recorder CPU a sample, 25 ms 10.2, 50 ms 9.4)
BATCH_PERIOD_S = 0.050
#: the most samples in one batch (a burst after a stall); about 7 KB, far below 64 KiB
MAX_BATCH_SAMPLES = 50


@dataclass(slots=True)
class _Batch:
    """One run's batch in progress."""

    due_s: float  # when it must go (monotonic seconds)
    samples: list[Sample] = field(default_factory=list)
    events: list[StickSlipEvent] = field(default_factory=list)
    intensities: list[Intensity] = field(default_factory=list)


class SampleBatching:
    """The samples of one station waiting for their batches, oldest first: one batch in
    progress per run, at most ``runs_at_once`` (a multi-spindle station's spindles run at
    once, their samples interleaved: each run's batch fills on its own)."""

    def __init__(
        self,
        station: str,
        period_s: float = BATCH_PERIOD_S,
        max_samples: int = MAX_BATCH_SAMPLES,
        runs_at_once: int = 1,
    ) -> None:
        self._station = station
        self._period_s = period_s
        self._max_samples = max_samples
        self._runs_at_once = runs_at_once
        self._batches: dict[int, _Batch] = {}  # by run id, oldest first

    def add(self, sample: Sample, now_s: float) -> list[SampleBatch]:
        """Append ``sample``; the batches that are ready now (none, one, or more when a new
        run starts while as many runs' batches are in progress, or others are due too),
        oldest first."""
        ready: list[SampleBatch] = []
        batches = self._batches
        batch = batches.get(sample.run_id)
        if batch is None:
            if len(batches) >= self._runs_at_once:
                ready.append(self._take(next(iter(batches))))
            batch = batches[sample.run_id] = _Batch(now_s + self._period_s)
        batch.samples.append(sample)
        if len(batch.samples) >= self._max_samples or now_s >= batch.due_s:
            ready.append(self._take(sample.run_id))
        if len(batches) > 1:  # the other runs' batches that are due (their samples stopped)
            ready += [self._take(run) for run in list(batches) if now_s >= batches[run].due_s]
        return ready

    def add_found(self, message: StickSlipEvent | Intensity) -> bool:
        """Put an event or its intensity into the batch in progress of its run, after its
        samples; False when none of its run is in progress (it goes alone)."""
        batch = self._batches.get(message.run_id)
        if batch is None:
            return False
        if isinstance(message, StickSlipEvent):
            batch.events.append(message)
        else:
            batch.intensities.append(message)
        return True

    def take(self) -> SampleBatch | None:
        """The oldest batch in progress (None when no sample waits); its run's next batch
        starts empty."""
        return self._take(next(iter(self._batches))) if self._batches else None

    def take_all(self) -> list[SampleBatch]:
        """Every batch in progress, oldest first (before anything else the station says)."""
        return [self._take(run) for run in list(self._batches)]

    def take_due(self, now_s: float) -> list[SampleBatch]:
        """The batches in progress that are due, oldest first."""
        batches = self._batches
        return [self._take(run) for run in list(batches) if now_s >= batches[run].due_s]

    def wait_s(self, now_s: float) -> float | None:
        """Seconds until the first batch in progress is due (0 when overdue); None when
        none is in progress."""
        if not self._batches:
            return None
        return max(0.0, min(batch.due_s for batch in self._batches.values()) - now_s)

    def _take(self, run_id: int) -> SampleBatch:
        batch = self._batches.pop(run_id)
        return SampleBatch(
            self._station, time.time_ns(), batch.samples, batch.events, batch.intensities
        )
