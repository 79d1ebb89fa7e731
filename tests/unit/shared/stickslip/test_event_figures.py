"""One figures type: the core's EventFigures, and the one conversion to StickSlipEvent."""

from __future__ import annotations

import dataclasses
import math

from shared.contract import RunClock, StickSlipEvent
from shared.stickslip import (
    HISTORY,
    EventFigures,
    EventHistory,
    PredictorCore,
    PredictorSettings,
    event_messages,
    stick_slip_event,
)
from tests.support.synthetic_runs import staircase

CORE_ONLY = {"current_force_n", "detected_at_s"}  # what the core keeps and the wire does not


def events_of_a_staircase() -> list[EventFigures]:
    core = PredictorCore(PredictorSettings(target_force_n=1e9))
    outputs = [o for row in staircase().rows() for o in core.update(*row)]
    return [o for o in outputs if isinstance(o, EventFigures)]


def test_the_message_carries_every_figure_of_the_event() -> None:
    events = events_of_a_staircase()
    assert len(events) > 5
    clock = RunClock(1_700_000_000_123_456_789)
    for event in events:
        message = stick_slip_event("st1", 7, clock, event)
        assert isinstance(message, StickSlipEvent)
        for figure in dataclasses.fields(EventFigures):
            if figure.name not in CORE_ONLY:
                assert getattr(message, figure.name) == getattr(event, figure.name), figure.name
        assert message.time_ns == clock.ns(event.time_s)
        assert message.predictions is not event.predictions  # a copy: the message owns its list
        assert (message.station, message.run_id) == ("st1", 7)


def test_the_intensity_message_comes_with_the_event() -> None:
    event = events_of_a_staircase()[3]
    message, intensity = event_messages("st1", 7, RunClock(0), event, 42)
    assert message.index == event.index
    assert intensity.time_ns == 42
    assert intensity.event_intensity == event.intensity
    assert intensity.process_intensity == event.process_intensity


def test_the_run_clock_converts_both_ways_to_the_nanosecond() -> None:
    clock = RunClock(1_700_000_000_000_000_000)
    for time_ns in (clock.started_ns, clock.started_ns + 1, clock.started_ns + 123_456_789_012):
        assert clock.ns(clock.seconds(time_ns)) == time_ns
    assert clock.seconds(clock.started_ns + 1_500_000_000) == 1.5
    assert clock.ns(0.001) == clock.started_ns + 1_000_000
    assert clock.ns_of([0.0, 0.5]) == [clock.started_ns, clock.started_ns + 500_000_000]
    assert clock.seconds_of([clock.started_ns + 2_000_000]) == [0.002]


def test_the_history_keeps_the_youngest_events_in_step() -> None:
    history = EventHistory()
    assert history.newest_time_s is None and not history.has(1)
    for j in range(1, 3 * HISTORY):
        plateau = None if j % 3 == 0 else 1000.0 * j
        period = None if j == 1 else 0.02
        history.add(0.02 * j, period, 10.0 + j, plateau, 100 * j, 5.0 * j)
    assert len(history.times_s) == len(history.peaks_nm) == HISTORY
    assert len(history.periods_s) == len(history.plateaus_n) == HISTORY
    assert history.newest_peak_nm == 10.0 + 3 * HISTORY - 1
    assert history.trough_index == 100 * (3 * HISTORY - 1)
    assert history.peaks_rise(3) and history.has(HISTORY)
    history.add(1.0, 0.02, 0.0, None, 0, math.nan)  # a lower peak: no staircase any more
    assert not history.peaks_rise(3)
