"""Missing and absurd input is resolved once, at the core's boundary.

A lost first ``JointSensors`` frame used to poison the force sums for the
whole run (no plateau, so no eq. 65 decision); one finite but absurd value
(1e300) silenced the detector and the stop rules for the rest of the run;
one timestamp an hour ahead made every later sample "out of order". Property
tests put the damage at random places and check that the core decides as it
does on the clean trace.
"""

from __future__ import annotations

import itertools
import math
from functools import cache

import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from shared.stickslip import CoreDecision, EventFigures, PredictorCore, PredictorSettings
from tests.support.synthetic_runs import SyntheticTrace, staircase

Row = tuple[float, float, float, float]  # time_s, torque_nm, force_n, angle_deg
TARGET_N = 30_400.0


@cache
def trace() -> SyntheticTrace:
    return staircase(torque_noise_nm=0.2, force_noise_n=30.0)


def outcome(rows: list[Row]) -> tuple[list[EventFigures], CoreDecision, PredictorCore]:
    core = PredictorCore(PredictorSettings(target_force_n=TARGET_N))
    outputs = [o for row in rows for o in core.update(*row)]
    events = [o for o in outputs if isinstance(o, EventFigures)]
    (decision,) = [o for o in outputs if isinstance(o, CoreDecision)]
    return events, decision, core


def closest_plateau_n() -> float:
    return min(trace().plateaus_n, key=lambda f: abs(f - TARGET_N))


def test_a_lost_first_force_frame_costs_one_sample_not_the_run() -> None:
    rows = trace().rows()
    clean_events, clean, _ = outcome(rows)
    t, tq, _, a = rows[0]
    events, decision, core = outcome([(t, tq, math.nan, a), *rows[1:]])
    with_plateau = [e for e in events if e.plateau_force_n is not None]
    assert len(with_plateau) == len([e for e in clean_events if e.plateau_force_n is not None])
    assert len(with_plateau) > 10  # was 0: the NaN had poisoned the running force sum
    assert (decision.reason, decision.time_s) == (clean.reason, clean.time_s)
    assert decision.reason == "plateau_closest"
    assert core.input_report.no_force == 1


@settings(max_examples=40, deadline=None)
@given(
    lost_at_start=st.integers(0, 60),
    lost=st.sets(st.integers(0, 999), max_size=250),
    gaps=st.lists(st.tuples(st.integers(50, 950), st.integers(1, 25)), max_size=4),
)
def test_missing_forces_and_samples_anywhere_leave_the_plateaus(
    lost_at_start: int, lost: set[int], gaps: list[tuple[int, int]]
) -> None:
    """Force frames lost at random (a run of them at the start too), samples lost in gaps."""
    skipped = {i for start, length in gaps for i in range(start, start + length)}
    rows = [
        (t, tq, math.nan if (i < lost_at_start or i in lost) else f, a)
        for i, (t, tq, f, a) in enumerate(trace().rows())
        if i not in skipped
    ]
    events, decision, core = outcome(rows)
    first_force = next(i for i, row in enumerate(rows) if not math.isnan(row[2]))
    assert core.input_report.no_force == first_force  # none to hold before the first
    after_first = [e for e in events if e.time_s >= rows[first_force][0]]
    assert len(after_first) > 20
    assert all(e.plateau_force_n is not None for e in after_first)
    assert all(math.isfinite(e.plateau_force_n or 0.0) for e in events)
    assert decision.reason in ("plateau_closest", "target_reached")
    assert decision.force_n is not None
    if not gaps:
        assert decision.force_n == pytest.approx(closest_plateau_n(), abs=150.0)
    else:  # a gap may hide the closest plateau: then the stop is within a step of the target
        plateaus = trace().plateaus_n
        step = max(b - a for a, b in itertools.pairwise(plateaus))
        assert abs(decision.force_n - TARGET_N) <= step


ABSURD = st.sampled_from([1e300, -1e300, 1e308, -1e308, math.inf, -math.inf, math.nan])


@settings(max_examples=60, deadline=None)
@given(index=st.integers(1, 900), column=st.integers(0, 3), value=ABSURD, count=st.integers(1, 3))
# three forces lost across a slip (its force step at 722): held, they once pulled the new
# plateau toward the old one and the stop went a plateau later (target_reached at 0.755 s)
@example(index=721, column=2, value=1e300, count=3)
def test_an_absurd_value_never_moves_the_decision(
    index: int, column: int, value: float, count: int
) -> None:
    """One to three samples with an absurd time, torque, force or angle: counted, not used.

    Two absurd timestamps among the run's first three samples cannot be told
    from its start (the guard's docstring): they are placed later.
    """
    if column == 0 and count > 1:
        index = max(index, 3)
    rows = trace().rows()
    clean_events, clean, _ = outcome(rows)
    damaged = [list(row) for row in rows]
    for i in range(index, index + count):
        damaged[i][column] = value
    events, decision, core = outcome([(r[0], r[1], r[2], r[3]) for r in damaged])
    report = core.input_report
    assert report.accepted >= len(rows) - count
    assert decision.reason == clean.reason
    assert decision.force_n == pytest.approx(clean.force_n, abs=100.0)
    assert decision.time_s == pytest.approx(clean.time_s, abs=0.0105)
    assert abs(len(events) - len(clean_events)) <= 1
    assert math.isfinite(events[-1].process_intensity)
    # within 5 %, and one event's intensity: the one event more or fewer allowed above (three
    # samples dropped at a slip's peak lose that slip: index 527, column 0, count 3, 5.4 %)
    largest_event = max(event.intensity or 0.0 for event in clean_events)
    clean_total = clean_events[-1].process_intensity
    assert abs(events[-1].process_intensity - clean_total) <= 0.05 * clean_total + largest_event


def test_a_sample_stamped_an_hour_ahead_is_one_bad_sample() -> None:
    rows = trace().rows()
    clean_events, clean, _ = outcome(rows)
    t, tq, f, a = rows[400]
    events, decision, core = outcome([*rows[:400], (t + 3600.0, tq, f, a), *rows[401:]])
    report = core.input_report
    assert (report.bad_time, report.out_of_order) == (1, 0)
    assert (decision.reason, decision.time_s) == (clean.reason, clean.time_s)
    assert len(events) == len(clean_events)


def test_a_real_gap_is_kept_and_counted() -> None:
    rows = trace().rows()
    gap_s = 0.030
    shifted = [*rows[:400], *[(t + gap_s, tq, f, a) for t, tq, f, a in rows[400:]]]
    _, decision, core = outcome(shifted)
    assert core.input_report.gaps == 1 and core.input_report.bad_time == 0
    assert core.input_report.accepted == len(rows)
    assert decision.reason in ("plateau_closest", "target_reached")


def test_a_torque_at_the_end_of_the_sensor_range_is_saturated_a_flat_one_is_not() -> None:
    """Real torque sits still for many samples (repeating its 1 mNm steps): not saturation."""
    core = PredictorCore(PredictorSettings(has_force=False))
    for i in range(200):
        core.update(i * 1e-3, 1.234, math.nan, 0.1 * i)
    assert core.input_report.saturated == 0
    for i in range(200, 205):
        core.update(i * 1e-3, 8388.607, math.nan, 0.1 * i)
    assert core.input_report.saturated == 5
