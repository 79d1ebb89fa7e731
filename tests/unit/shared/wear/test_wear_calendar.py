"""The production calendar learned from the ledger's runs: day start, weekdays, shifts."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from shared.wear.wear_calendar import DAY_NS, ProductionCalendar, learn_calendar
from tests.support.wear_plant import ONE_SHIFT, THREE_SHIFTS, TWO_SHIFTS, PlantShape, simulate

HOUR_S = 3600


def hours(seconds: int) -> float:
    return round(seconds / HOUR_S, 2)


def learned(shape_days: int, shape: PlantShape = TWO_SHIFTS) -> ProductionCalendar:
    plant = simulate(replace(shape, days=shape_days, holidays=0), seed=5)
    calendar = learn_calendar(plant.ended_ns)
    assert calendar is not None
    return calendar


def test_a_two_shift_week_is_learned_from_its_runs() -> None:
    calendar = learned(35)
    # 06:00 local at UTC+1, less half the 30 min hand-over: the first runs at 05:15 UTC
    assert hours(calendar.day_start_s) == 5.25
    weights = [round(day.weight, 1) for day in calendar.weekdays]
    assert weights == [1.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0]
    shifts = [(hours(s.start_s), hours(s.end_s)) for s in calendar.weekdays[0].shifts]
    # 05:15-12:45 and 13:15-20:45 UTC (each shift less its hand-over), from the day's start
    assert shifts == [(0.0, 7.5), (8.0, 15.5)]
    assert calendar.weekdays[6].shifts == []


def test_three_shifts_and_a_saturday_morning_are_counted_shift_by_shift() -> None:
    calendar = learned(35, THREE_SHIFTS)
    # the day starts with the night shift (22:00 local, UTC-5): Monday's day holds its
    # morning and afternoon only, Saturday's day Friday's night and Saturday's morning
    assert hours(calendar.day_start_s) == 3.25
    shifts = [len(day.shifts) for day in calendar.weekdays]
    assert shifts == [2, 3, 3, 3, 3, 2, 0]
    mean = sum(shifts) / 6
    for day, count in zip(calendar.weekdays, shifts, strict=True):
        assert day.weight == pytest.approx(count / mean, rel=0.1)


def test_a_lunch_break_splits_the_day_and_a_holiday_leaves_the_weekday_worked() -> None:
    plant = simulate(replace(ONE_SHIFT, days=35, holidays=1), seed=5)
    calendar = learn_calendar(plant.ended_ns)
    assert calendar is not None
    # 07:00 local at UTC+8 is 23:00 UTC the evening before: the day is the local date's
    assert hours(calendar.day_start_s) == -1.0
    assert [day.weight > 0 for day in calendar.weekdays] == [True] * 6 + [False]
    assert len(calendar.weekdays[2].shifts) == 2


def test_worked_time_runs_from_0_to_1_over_the_shifts_and_back() -> None:
    calendar = learned(21)
    monday = next(d for d in range(20_000, 20_007) if calendar.weekday(d) == 0)
    start = calendar.day_start_ns(monday)
    assert calendar.worked_fraction(start) == 0.0
    assert calendar.worked_fraction(start + DAY_NS - 1) == 1.0
    # in the hand-over between the shifts: half of the day's worked time
    assert calendar.worked_fraction(start + int(7.75 * HOUR_S * 1e9)) == pytest.approx(0.5)
    for fraction in (0.1, 0.5, 0.9):
        assert calendar.worked_fraction(calendar.time_at(monday, fraction)) == pytest.approx(
            fraction, abs=1e-9
        )
    saturday = monday + 5
    assert not calendar.worked(saturday)
    assert calendar.shift_at(calendar.day_start_ns(saturday)) == (
        calendar.day_start_ns(monday + 7),
        calendar.day_start_ns(monday + 7) + int(7.5 * HOUR_S * 1e9),
    )


def test_less_than_a_week_of_runs_is_no_calendar() -> None:
    plant = simulate(replace(TWO_SHIFTS, days=6, holidays=0), seed=5)
    assert learn_calendar(plant.ended_ns) is None
    assert learn_calendar(np.zeros(0, dtype=np.int64)) is None


def test_a_calendar_survives_its_json() -> None:
    calendar = learned(14)
    from dataclasses import asdict

    assert ProductionCalendar.from_dict(asdict(calendar)) == calendar
