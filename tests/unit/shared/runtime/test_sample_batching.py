"""An edge station's batch in progress: when it goes, and what rides in it."""

from __future__ import annotations

import pytest

from shared.contract import Intensity
from shared.runtime import BATCH_PERIOD_S, MAX_BATCH_SAMPLES, SampleBatching
from tests.support.factories import MS, T0, event, sample


def test_a_batch_goes_when_due_full_or_at_a_new_run() -> None:
    batching = SampleBatching("st1")
    assert batching.add(sample(1, 0), 0.0) == []
    assert batching.wait_s(0.0) == BATCH_PERIOD_S
    (due,) = batching.add(sample(1, 1), BATCH_PERIOD_S)
    assert [s.sequence for s in due.samples] == [0, 1]
    batching.add(sample(1, 2), 1.0)
    (first_run,) = batching.add(sample(2, 0), 1.0)  # never two runs in one batch
    assert [s.run_id for s in first_run.samples] == [1]
    ready = [b for n in range(1, MAX_BATCH_SAMPLES) for b in batching.add(sample(2, n), 1.0)]
    assert [len(b.samples) for b in ready] == [MAX_BATCH_SAMPLES]


def test_events_and_intensities_ride_in_the_batch_of_their_run_after_its_samples() -> None:
    batching = SampleBatching("st1")
    assert not batching.add_found(event(1, 1))  # no batch in progress: it goes alone
    batching.add(sample(1, 0), 0.0)
    assert not batching.add_found(event(2, 1))  # not this batch's run
    figures = Intensity("st1", 1, T0 + MS, 0.5, 0.5)
    assert batching.add_found(event(1, 1)) and batching.add_found(figures)
    batching.add(sample(1, 1), 0.001)
    batch = batching.take()
    assert batch is not None
    assert [s.sequence for s in batch.samples] == [0, 1]
    assert (batch.events, batch.intensities) == ([event(1, 1)], [figures])
    assert batching.take() is None  # the next batch starts empty
    batching.add(sample(1, 2), 0.002)
    after = batching.take()
    assert after is not None and (after.events, after.intensities) == ([], [])


def test_a_multi_spindle_stations_runs_each_fill_a_batch_of_their_own() -> None:
    """Four spindles' samples interleaved: four batches in progress, each of one run and as
    full as a single spindle's; an event rides in its own run's; all go before anything
    else the station says, oldest first."""
    batching = SampleBatching("st1", runs_at_once=4)
    ready = [
        b for n in range(10) for run in (1, 2, 3, 4) for b in batching.add(sample(run, n), 0.0)
    ]
    assert ready == []
    assert batching.add_found(event(3, 1)) and not batching.add_found(event(5, 1))
    due = batching.add(sample(1, 10), BATCH_PERIOD_S)  # every batch is due now
    assert [(b.samples[0].run_id, len(b.samples)) for b in due] == [
        (1, 11),
        (2, 10),
        (3, 10),
        (4, 10),
    ]
    assert [b.events for b in due] == [[], [], [event(3, 1)], []]
    for run in (1, 2):
        batching.add(sample(run, 11), 1.0)
    assert batching.wait_s(1.0) == pytest.approx(BATCH_PERIOD_S)
    assert [b.samples[0].run_id for b in batching.take_all()] == [1, 2]
    assert batching.take() is None
    # a fifth run while four are in progress: the oldest goes
    for run in (1, 2, 3, 4):
        batching.add(sample(run, 12), 2.0)
    (oldest,) = batching.add(sample(5, 0), 2.0)
    assert oldest.samples[0].run_id == 1
    assert [b.samples[0].run_id for b in batching.take_due(2.0 + BATCH_PERIOD_S)] == [2, 3, 4, 5]
