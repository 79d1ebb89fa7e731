"""A tool's pace and its service forecast against a threshold (pure)."""

from __future__ import annotations

import math

import pytest

from shared.wear.wear_calendar import DAY_NS, ProductionCalendar, ProductionWeekday, Shift
from shared.wear.wear_change import WorkChange
from shared.wear.wear_forecast import DayWear, ForecastSettings, WearPace, forecast, wear_pace

HOUR_NS = 3_600_000_000_000
#: two shifts of 8 h from 06:00 UTC, Monday to Friday
WEEKDAY = ProductionWeekday(1.0, [Shift(0, 8 * 3600), Shift(8 * 3600, 16 * 3600)])
CALENDAR = ProductionCalendar(6 * 3600, [WEEKDAY] * 5 + [ProductionWeekday(0.0)] * 2, 0, 0, 0)
#: a Monday (2026-11-02), its day number
MONDAY = 20_759
assert CALENDAR.weekday(MONDAY) == 0


def days(first: int, count: int, per_day: float = 1000.0, wobble: float = 0.0) -> list[DayWear]:
    """``count`` worked days from ``first`` (weekends skipped), 100 runs each."""
    found: list[DayWear] = []
    day = first
    while len(found) < count:
        if CALENDAR.worked(day):
            value = per_day * (1 + wobble * (1 if len(found) % 2 else -1))
            found.append(DayWear(day, 100, 100, value, value * value / 100))
        day += 1
    return found


def monday_at(hour: float, weeks: int = 4) -> int:
    return CALENDAR.day_start_ns(MONDAY + 7 * weeks) + int((hour - 6) * HOUR_NS)


def steady_pace(now_ns: int, wobble: float = 0.1) -> WearPace:
    return wear_pace(
        days(MONDAY, 20, wobble=wobble), CALENDAR, CALENDAR.day_start_ns(MONDAY), now_ns, now_ns
    )


def test_the_pace_is_the_intensity_per_production_day_and_its_spread() -> None:
    now_ns = monday_at(6)  # Monday 06:00, the start of its first shift: 20 days behind it
    pace = steady_pace(now_ns)
    assert pace.note is None
    assert pace.days == 20
    assert pace.per_day == pytest.approx(1000.0, rel=0.01)
    assert pace.day_spread == pytest.approx(100.0, rel=0.1)
    assert pace.per_run == pytest.approx(10.0, rel=0.01)


def test_a_steady_tool_is_due_the_day_its_pace_brings_it_there_and_weekends_do_not_count() -> None:
    now_ns = monday_at(6)
    pace = steady_pace(now_ns, wobble=0.0)
    told = forecast(7, pace, CALENDAR, 1000.0, 7_500.0, now_ns)
    assert told.state == "forecast"
    # 6 500 left at 1 000 a day: 6.5 production days, Monday 06:00 + 6.5 days skips the weekend
    assert told.production_days == pytest.approx(6.5)
    assert told.due_ns == CALENDAR.time_at(MONDAY + 28 + 8, 0.5)  # Tuesday of the next week
    assert told.runs_left == 650
    # no spread, no drift: the interval is the date itself
    exact = forecast(7, pace, CALENDAR, 1000.0, 7_500.0, now_ns, ForecastSettings(drift=0.0))
    assert exact.early_ns == exact.due_ns == exact.late_ns


def test_the_interval_holds_the_date_and_widens_with_the_horizon() -> None:
    now_ns = monday_at(10)
    pace = steady_pace(now_ns)
    near = forecast(7, pace, CALENDAR, 0.0, 2_000.0, now_ns)
    far = forecast(7, pace, CALENDAR, 0.0, 20_000.0, now_ns)
    for told in (near, far):
        assert told.early_ns is not None and told.late_ns is not None and told.due_ns is not None
        assert now_ns < told.early_ns < told.due_ns < told.late_ns
        assert told.runs_left_low is not None and told.runs_left_high is not None
        assert told.runs_left_low <= (told.runs_left or 0) <= told.runs_left_high
    assert near.production_days_early is not None and far.production_days_early is not None
    assert near.production_days_late is not None and far.production_days_late is not None
    near_width = near.production_days_late - near.production_days_early
    far_width = far.production_days_late - far.production_days_early
    assert far_width > 3 * near_width
    # plan the service at the last shift change before the early end, not before now
    assert far.service_by_ns is not None and far.early_ns is not None
    assert now_ns <= far.service_by_ns <= far.early_ns
    assert CALENDAR.worked_fraction(far.service_by_ns) in (0.0, 0.5)


def test_a_tool_past_its_threshold_is_due_with_no_run_left() -> None:
    now_ns = monday_at(10)
    told = forecast(7, steady_pace(now_ns), CALENDAR, 8_000.0, 7_500.0, now_ns)
    assert (told.state, told.runs_left, told.due_ns) == ("due", 0, None)
    assert told.intensity_left == 0.0


def test_no_threshold_or_too_little_history_gives_no_date_but_the_reason() -> None:
    now_ns = monday_at(10)
    unset = forecast(7, steady_pace(now_ns), CALENDAR, 100.0, None, now_ns)
    assert unset.state == "none" and unset.reason is not None and "threshold" in unset.reason
    young = wear_pace(days(MONDAY + 25, 3), CALENDAR, now_ns - 5 * DAY_NS, now_ns, now_ns)
    assert young.note is not None and "7 days of history" in young.note
    told = forecast(7, young, CALENDAR, 100.0, 5_000.0, now_ns)
    assert (told.state, told.due_ns) == ("none", None)
    assert told.reason == young.note
    idle = wear_pace([], CALENDAR, now_ns - 90 * DAY_NS, now_ns - 80 * DAY_NS, now_ns)
    assert idle.note is not None and "complete production days" in idle.note
    assert wear_pace(days(MONDAY, 20), None, 0, now_ns, now_ns).note is not None


def test_after_its_work_changed_the_pace_is_measured_from_the_change() -> None:
    now_ns = monday_at(6)
    before = days(MONDAY, 15)
    after = days(MONDAY + 21, 3, per_day=3000.0)  # the Monday to Wednesday of the 4th week
    change = WorkChange(MONDAY + 21, "moved to st2")
    mixed = wear_pace(before + after, CALENDAR, 0, now_ns, now_ns)
    moved = wear_pace(before + after, CALENDAR, 0, now_ns, now_ns, change=change)
    assert mixed.per_day < 2000.0
    assert moved.per_day == pytest.approx(3000.0)
    assert moved.basis is not None and "moved to st2" in moved.basis


def test_a_slow_end_that_never_gets_there_in_two_years_has_no_late_date() -> None:
    now_ns = monday_at(10)
    pace = steady_pace(now_ns)
    told = forecast(7, pace, CALENDAR, 0.0, 1e5, now_ns, ForecastSettings(drift=2.0))
    assert told.state == "forecast" and told.late_ns is None
    assert told.production_days is not None and math.isfinite(told.production_days)
