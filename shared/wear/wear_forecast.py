"""When a tool comes due for service: its pace of wear and the forecast from it (pure, numpy).

**The pace** (:func:`wear_pace`): the tool's intensity (Σ I_process, eq. 69)
per production day, from the complete production days it ran in the last
:attr:`ForecastSettings.window_days` days (at every station it ran at).
Each day's intensity is divided by its weekday's weight (a Saturday of one
shift counts half a day, :mod:`.wear_calendar`) and the days are weighed by
age, halving every :attr:`ForecastSettings.half_life_days` production days
(a program added or a tool moved to another station shows within a week):

    r = Σ a_j x_j / Σ a_j,   x_j = d_j / w_j,   a_j = 2^(-age_j / h)

with its day-to-day spread s (the weighted standard deviation of the x_j)
and the effective number of days m = (Σ a_j)² / Σ a_j². The same for one
run (intensity per tightening, its spread).

**The forecast** (:func:`forecast`): the intensity left to the threshold,
R = T - I_since_service, against what the coming production days bring
(the rest of today's worked time, then each worked day by its weight).
After u production days the tool has taken S(u), with

    E[S(u)] = r u,   Var[S(u)] = s² u + u² (s² / m + (κ r)²)

(day-to-day spread, the pace's own uncertainty, and κ: how far a pace
drifts, a relative standard deviation tuned on simulated plants,
``tests/benchmarks/bench_wear_forecast.py``). The forecast date is where
E[S(u)] = R; the 80 % interval is where E[S(u)] ± z σ(u) = R, z the
normal 90 % quantile: a faster pace makes the early end, a slower the late
end (none when even two years would not bring the tool to its threshold
at the slow end). Runs left: R over the intensity per run, with the same
interval from the spread of one run.

A tool whose first run is less than :attr:`ForecastSettings.min_history_days`
days old, that ran on fewer than :attr:`ForecastSettings.min_days` complete
production days in the window, or whose runs took no intensity, gets no
date: the reason instead (:attr:`WearPace.note`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from statistics import NormalDist
from typing import Any, Literal

import numpy as np

from shared.wear.wear_calendar import DAY_NS, WEEK_DAYS, ProductionCalendar
from shared.wear.wear_change import WorkChange

#: the share of outcomes the stated interval is for
INTERVAL = 0.8
_Z = NormalDist().inv_cdf(0.5 + INTERVAL / 2)
#: the most a pace's day-to-day memory is taken to be (ρ; the spread of a sum of days grows
#: by (1 + ρ) / (1 - ρ))
MAX_MEMORY = 0.8
#: the furthest a forecast looks, in production days (about two years)
HORIZON_DAYS = 500


@dataclass(frozen=True, slots=True)
class ForecastSettings:
    """How the pace is measured and how sure the forecast is (tuned on simulated plants)."""

    window_days: int = 42  # calendar days of history the pace is measured over
    half_life_days: float = 21.0  # production days after which a day counts half
    drift: float = 0.06  # κ: the relative standard deviation of a pace's drift
    min_history_days: int = 7  # a tool's first run at least this old (calendar days)
    min_days: int = 3  # complete production days it ran in the window
    #: after a change of its work (:mod:`.wear_change`), the pace is measured from the change
    #: once it ran on this many complete production days since
    min_days_since_change: int = 2


#: the settings boltwatch forecasts with (tuned: ``tests/benchmarks/bench_wear_forecast.py``)
SHIPPED = ForecastSettings()


@dataclass(frozen=True, slots=True)
class DayWear:
    """One production day of one tool (every station it ran at)."""

    day: int  # the production day (:meth:`ProductionCalendar.day_of`)
    runs: int  # its tightenings
    every_run: int  # its runs of either kind (loosenings too)
    intensity: float  # Σ I_process of its runs
    intensity_sq: float  # Σ I_process² (the spread of one run)


@dataclass(frozen=True, slots=True)
class WearPace:
    """How fast a tool takes wear, from its recent production days."""

    per_day: float  # intensity per production day (of weight 1)
    day_spread: float  # standard deviation of one day's intensity around it
    days: int  # complete production days it ran in the window
    effective_days: float  # m: the days' count with their weights
    #: ρ: how much one day's intensity follows the day before's (0 to MAX_MEMORY)
    day_memory: float
    per_run: float  # intensity per tightening (loosenings' intensity included)
    run_spread: float  # standard deviation of one run's intensity
    first_run_ns: int  # the tool's first run in the ledger
    last_run_ns: int  # its newest
    note: str | None = None  # why no forecast is made from it; None: one is
    #: what it is measured over when not the whole window: since the tool's work changed
    basis: str | None = None

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


ForecastState = Literal["forecast", "due", "none"]


@dataclass(frozen=True, slots=True)
class ToolForecast:
    """A tool's service forecast at one moment against one threshold."""

    tool_id: int
    made_ns: int  # when it was made
    state: ForecastState  # forecast: a date; due: past its threshold; none: see reason
    reason: str | None  # why no date (state "none"), or what "due" means
    threshold: float | None
    intensity_since_service: float
    intensity_left: float  # to the threshold (0 when due)
    runs_left: int | None  # tightenings to the threshold, at the recent intensity per run
    runs_left_low: int | None  # its 80 % interval
    runs_left_high: int | None
    due_ns: int | None  # the forecast date of the threshold crossing
    early_ns: int | None  # its 80 % interval: early end
    late_ns: int | None  # late end (None: beyond two years at the slow end)
    production_days: float | None  # production days from now to due_ns
    production_days_early: float | None
    production_days_late: float | None
    per_day: float | None  # the pace: intensity per production day
    service_by_ns: int | None  # the last shift change before the early end: plan it there

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def wear_pace(
    days: Sequence[DayWear],
    calendar: ProductionCalendar | None,
    first_run_ns: int,
    last_run_ns: int,
    now_ns: int,
    settings: ForecastSettings = SHIPPED,
    change: WorkChange | None = None,
) -> WearPace:
    """The tool's pace from its ``days`` (any order; today's and older than the window are
    left out here), ``calendar`` the plant's (None: not learned yet); from ``change`` on when
    its work changed (:func:`~.wear_change.work_changed`) and enough days followed."""
    # with too little history for a date, the runs left still go by its runs so far
    per_run, run_spread = _run_figures(days, np.ones(len(days)))
    empty = WearPace(0.0, 0.0, 0, 0.0, 0.0, per_run, run_spread, first_run_ns, last_run_ns)
    history_days = (now_ns - first_run_ns) / DAY_NS
    if history_days < settings.min_history_days:
        return _with_note(
            empty,
            f"first run {history_days:.1f} days ago: a forecast needs "
            f"{settings.min_history_days} days of history",
        )
    if calendar is None:
        return _with_note(empty, "the ledger holds less than a week of production: no calendar")
    today = calendar.day_of(now_ns)
    oldest = calendar.day_of(now_ns - settings.window_days * DAY_NS)
    kept = sorted(
        (day for day in days if oldest <= day.day < today and day.every_run > 0),
        key=lambda day: day.day,
    )
    if len(kept) < settings.min_days:
        return _with_note(
            empty,
            f"ran on {len(kept)} complete production days in the last {settings.window_days} "
            f"days: a forecast needs {settings.min_days}",
        )
    basis = None
    if change is not None:
        since = [day for day in kept if day.day >= change.day]
        if len(since) >= settings.min_days_since_change:
            kept = since
            basis = (
                f"the {len(since)} production days since the tool's work changed ({change.what})"
            )
    weights = np.array([calendar.of_day(day.day).weight or 1.0 for day in kept])
    intensity = np.array([day.intensity for day in kept])
    ages = np.arange(len(kept))[::-1]  # the newest day it ran: 0
    age_weights = 0.5 ** (ages / settings.half_life_days)
    per_weight = intensity / weights
    total = float(age_weights.sum())
    per_day = float((age_weights * per_weight).sum() / total)
    squares = float((age_weights**2).sum())
    spread = math.sqrt(
        float((age_weights * (per_weight - per_day) ** 2).sum())
        / max(total - squares / total, 1e-9)
    )
    per_run, run_spread = _run_figures(kept, age_weights)
    pace = WearPace(
        per_day=per_day,
        day_spread=spread,
        days=len(kept),
        effective_days=total * total / squares,
        day_memory=_memory(per_weight),
        per_run=per_run,
        run_spread=run_spread,
        first_run_ns=first_run_ns,
        last_run_ns=last_run_ns,
        basis=basis,
    )
    if per_day <= 0:
        return _with_note(pace, "its runs took no stick-slip intensity: not due at this pace")
    return pace


def _run_figures(days: Sequence[DayWear], weights: np.ndarray) -> tuple[float, float]:
    """The intensity per tightening of ``days`` (weighed), and the spread of one run's."""
    if not days:
        return 0.0, 0.0
    intensity = np.array([day.intensity for day in days])
    runs = np.array([day.runs or day.every_run for day in days], dtype=float)
    counts = np.array([day.every_run for day in days], dtype=float)
    squares = np.array([day.intensity_sq for day in days])
    if float((weights * counts).sum()) <= 0:
        return 0.0, 0.0
    per_run = float((weights * intensity).sum() / (weights * runs).sum())
    mean_each = float((weights * intensity).sum() / (weights * counts).sum())
    mean_sq = float((weights * squares).sum() / (weights * counts).sum())
    return per_run, math.sqrt(max(mean_sq - mean_each**2, 0.0))


def _memory(values: np.ndarray) -> float:
    """The lag-1 autocorrelation of the days' values, from 0 to :data:`MAX_MEMORY` (a pace
    whose days follow each other wanders further than one of independent days)."""
    if values.size < 4:
        return 0.0
    centred = values - values.mean()
    spread = float((centred**2).sum())
    if spread <= 0:
        return 0.0
    estimate = float((centred[1:] * centred[:-1]).sum()) / spread
    # a short series' estimate falls short of ρ by about (1 + 3ρ) / n (Kendall, 1954)
    estimate += (1 + 3 * estimate) / values.size
    return min(max(estimate, 0.0), MAX_MEMORY)


def _with_note(pace: WearPace, note: str) -> WearPace:
    return WearPace(**(asdict(pace) | {"note": note}))


def forecast(
    tool_id: int,
    pace: WearPace | None,
    calendar: ProductionCalendar | None,
    intensity_since_service: float,
    threshold: float | None,
    now_ns: int,
    settings: ForecastSettings = SHIPPED,
) -> ToolForecast:
    """The forecast of ``tool_id`` now (``pace`` None: no pace known, e.g. a plant's merge)."""
    base = ToolForecast(
        tool_id=tool_id,
        made_ns=now_ns,
        state="none",
        reason=None,
        threshold=threshold,
        intensity_since_service=intensity_since_service,
        intensity_left=0.0 if threshold is None else max(threshold - intensity_since_service, 0),
        runs_left=None,
        runs_left_low=None,
        runs_left_high=None,
        due_ns=None,
        early_ns=None,
        late_ns=None,
        production_days=None,
        production_days_early=None,
        production_days_late=None,
        per_day=None if pace is None or pace.note else pace.per_day,
        service_by_ns=None,
    )
    if threshold is None:
        return _replace(base, reason="no service threshold set (recorder.wear_service_threshold)")
    if intensity_since_service >= threshold:
        return _replace(
            base, state="due", reason="past its service threshold: due now", runs_left=0
        )
    if pace is None:
        return _replace(base, reason="no pace known")
    left = threshold - intensity_since_service
    runs = _runs_left(pace, left, settings) if pace.per_run > 0 else (None, None, None)
    base = _replace(base, runs_left=runs[0], runs_left_low=runs[1], runs_left_high=runs[2])
    if pace.note is not None or calendar is None:
        return _replace(base, reason=pace.note or "no production calendar")
    days = _days_to(left, pace, settings)
    if days[0] is None:
        return _replace(base, reason="not due within two years at this pace")
    walk = _CalendarWalk(calendar, now_ns)
    due = walk.at(days[0])
    early = walk.at(days[1]) if days[1] is not None else None
    late = walk.at(days[2]) if days[2] is not None else None
    if due is None:
        return _replace(base, reason="no worked day ahead in the production calendar")
    return _replace(
        base,
        state="forecast",
        due_ns=due[0],
        early_ns=early[0] if early else None,
        late_ns=late[0] if late else None,
        production_days=due[1],
        production_days_early=early[1] if early else None,
        production_days_late=late[1] if late else None,
        service_by_ns=_change_before(calendar, early[0] if early else due[0], now_ns),
    )


def _replace(forecast_: ToolForecast, **changes: Any) -> ToolForecast:
    return ToolForecast(**(asdict(forecast_) | changes))


def _days_to(
    left: float, pace: WearPace, settings: ForecastSettings
) -> tuple[float | None, float | None, float | None]:
    """Weighted production days until ``left`` is taken: median, early end, late end."""
    rho = pace.day_memory
    spread_sq = pace.day_spread**2
    # the pace's own uncertainty: its days count as fewer when they follow each other
    square = (
        spread_sq * (1 + rho) / (1 - rho) / max(pace.effective_days, 1.0)
        + (settings.drift * pace.per_day) ** 2
    )
    median = left / pace.per_day

    def reached(u: float, z: float) -> float:
        variance = spread_sq * _days_of_sum(u, rho) + square * u * u
        return pace.per_day * u + z * math.sqrt(variance) - left

    early = _solve(lambda u: reached(u, _Z), 0.0, median)
    late = _solve(lambda u: reached(u, -_Z), median, float(HORIZON_DAYS))
    return (median if median <= HORIZON_DAYS else None), early, late


def _days_of_sum(u: float, rho: float) -> float:
    """Var[sum of u days] / s² for days whose values follow an AR(1) of lag-1 correlation
    ``rho``: u (1 + ρ) / (1 - ρ) - 2 ρ (1 - ρ^u) / (1 - ρ)² (u for independent days; one
    day for u = 1)."""
    if rho <= 0:
        return u
    return max(u * (1 + rho) / (1 - rho) - 2 * rho * (1 - rho**u) / (1 - rho) ** 2, 0.0)


def _solve(function: Any, low: float, high: float) -> float | None:
    """The root of an increasing ``function`` in [low, high] by bisection; None when it stays
    below zero there."""
    if function(high) < 0:
        return None
    if function(low) >= 0:
        return low
    for _ in range(60):
        middle = (low + high) / 2
        if function(middle) < 0:
            low = middle
        else:
            high = middle
    return high


def _runs_left(
    pace: WearPace, left: float, settings: ForecastSettings
) -> tuple[int, int | None, int | None]:
    """Tightenings until ``left`` is taken: at the recent intensity per run, and the 80 %
    interval from the spread of one run and the drift of the pace."""
    mean = pace.per_run
    linear = pace.run_spread**2
    square = (settings.drift * mean) ** 2

    def reached(n: float, z: float) -> float:
        return mean * n + z * math.sqrt(linear * n + square * n * n) - left

    median = left / mean
    low = _solve(lambda n: reached(n, _Z), 0.0, median)
    high = _solve(lambda n: reached(n, -_Z), median, median * 100 + 10)
    return (
        _whole_runs(median),
        None if low is None else _whole_runs(low),
        None if high is None else _whole_runs(high),
    )


def _whole_runs(runs: float) -> int:
    """The runs it takes, whole (a sum's last bit of rounding is no run more)."""
    return math.ceil(round(runs, 6))


class _CalendarWalk:
    """From now along the production calendar: the moment ``u`` weighted production days on,
    and how many production days that is."""

    def __init__(self, calendar: ProductionCalendar, now_ns: int) -> None:
        self._calendar = calendar
        self._now_ns = now_ns
        self._today = calendar.day_of(now_ns)
        weight = calendar.of_day(self._today).weight
        self._done_today = calendar.worked_fraction(now_ns) if weight > 0 else 1.0
        self._week_weight = sum(day.weight for day in calendar.weekdays)
        self._week_days = sum(1 for day in calendar.weekdays if day.weight > 0)

    def at(self, u: float) -> tuple[int, float] | None:
        """(the moment, production days from now) ``u`` weighted days on; None when no
        day is worked."""
        if self._week_weight <= 0:
            return None
        calendar = self._calendar
        weight = calendar.of_day(self._today).weight
        rest = weight * (1.0 - self._done_today)
        if u <= rest and weight > 0:
            fraction = self._done_today + u / weight
            return calendar.time_at(self._today, fraction), u / weight
        u -= rest
        counted = 1.0 - self._done_today if weight > 0 else 0.0
        day = self._today + 1
        weeks = max(int(u // self._week_weight) - 1, 0)  # whole weeks skipped at once
        u -= weeks * self._week_weight
        counted += weeks * self._week_days
        day += weeks * WEEK_DAYS
        while True:
            weight = calendar.of_day(day).weight
            if weight > 0:
                if u <= weight:
                    return calendar.time_at(day, u / weight), counted + u / weight
                u -= weight
                counted += 1.0
            day += 1


def _change_before(calendar: ProductionCalendar, time_ns: int, now_ns: int) -> int:
    """The last shift change (a shift's start or end) at or before ``time_ns``, not before
    ``now_ns``: when to plan a service that must come before ``time_ns``."""
    day = calendar.day_of(time_ns)
    for back in range(WEEK_DAYS + 1):
        start_ns = calendar.day_start_ns(day - back)
        changes = [
            start_ns + int(second * 1e9)
            for shift in calendar.of_day(day - back).shifts
            for second in (shift.start_s, shift.end_s)
        ]
        before = [change for change in changes if change <= time_ns]
        if before:
            return max(*before, now_ns)
    return now_ns
