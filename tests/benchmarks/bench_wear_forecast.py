"""The wear forecast's backtest: forecasts made 30, 14, 7 and 1 production days before each
threshold crossing of simulated plants, against the crossing that came.

Run: ``.venv/bin/python tests/benchmarks/bench_wear_forecast.py [--tune] [--quick] [--cost]``
(not collected by pytest; a few minutes). Each plant (``tests/support/wear_plant.py``: a
shape and a seed; months of shifts, weekends, holidays, a program added midway, tools
swapped between stations, services at the shift change after each crossing) is written
into a real wear ledger, and each forecast reads it as the live code does, as of the
moment it is made (:mod:`shared.wear.wear_history`: the calendar learned from the
ledger, the tool's runs grouped by production day), then
:func:`shared.wear.wear_forecast.forecast` against the plant's threshold.

Per horizon: the cases (a crossing with a forecast moment inside its service interval),
how many got no date, the median and 90th percentile of the absolute error in production
days (the plant's own: holidays are not production days, which the forecast cannot know),
the mean error (negative: early) and how often the stated 80 % interval held the
crossing. Then the tools' first week: how many forecasts in a tool's first seven days
gave a date (none should).

``--tune`` searches the settings (half-life, window, drift) on the tuning plants (shapes
"two" and "three", seeds 1 and 2) and prints the best; the figures that count are those
of the judging plants (other seeds, and the shape "one" never tuned on), printed with the
shipped settings (:class:`~shared.wear.wear_forecast.ForecastSettings`).

``--cost``: what the forecast adds to the recorder's work per counted run, on a plant's
eight months of runs (two shifts, five stations): runs counted through the recorder's
:class:`~services.recorder.wear_watch.WearWatch` with a threshold, with the forecast's
horizons and without, alternating, the medians of five rounds in ms per run; and one
``boltwatch wear`` reading of the plant's tools (``WearLedger.tools``, with their outlooks).
"""

from __future__ import annotations

import argparse
import itertools
import sqlite3
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from shared.wear.wear_calendar import DAY_NS, ProductionCalendar
from shared.wear.wear_forecast import ForecastSettings, forecast
from shared.wear.wear_grouped_runs import GroupedRuns
from shared.wear.wear_history import first_and_last, grouped_runs, ledger_calendar
from shared.wear.wear_ledger_file import identity
from shared.wear.wear_outlook import tool_outlook
from tests.support.wear_plant import SHAPES, Crossing, Plant, simulate, write_ledger

HORIZONS = (30, 14, 7, 1)
TUNING = tuple((shape, seed) for shape in ("two", "three") for seed in (1, 2, 3, 4))
JUDGING = tuple((shape, seed) for shape in ("two", "three", "one") for seed in (11, 12, 13))
#: the longest window tried: every case's runs are read over it once
READ_WINDOW_DAYS = 98


@dataclass(frozen=True)
class Case:
    """One forecast moment: what the ledger held then, and the crossing that came."""

    plant: Plant
    crossing: Crossing
    ahead_days: int
    made_ns: int
    groups: list[GroupedRuns]
    calendar: ProductionCalendar | None
    span: tuple[int, int]
    serviced_ns: int | None
    since_service: float


def read_cases(plant: Plant, path: Path) -> tuple[list[Case], list[Case]]:
    """The backtest's cases, and the first-week ones (a tool's 1st to 6th day)."""
    db = sqlite3.connect(f"{path.resolve().as_uri()}?mode=ro", uri=True)
    file = identity(path)
    try:
        moments = []
        for crossing in plant.crossings:
            crossed = plant.calendar.position(crossing.crossed_ns)
            for ahead in HORIZONS:
                made_ns = plant.calendar.time_at(crossed - ahead)
                if made_ns > crossing.interval_start_ns:
                    moments.append((made_ns, crossing, ahead))
        first_week = []
        for tool, first_ns in plant.first_run_ns.items():
            for day in range(1, 7):
                first_week.append((first_ns + day * DAY_NS, Crossing(tool, first_ns, 0, 0), 0))
        cases = [_case(db, file, plant, *moment) for moment in sorted(moments, key=lambda m: m[0])]
        early = [_case(db, file, plant, *moment) for moment in first_week]
    finally:
        db.close()
    return cases, early


def _case(
    db: sqlite3.Connection,
    file: tuple[int, int],
    plant: Plant,
    made_ns: int,
    crossing: Crossing,
    ahead: int,
) -> Case:
    with db:
        db.execute("BEGIN")
        calendar = ledger_calendar(db, file, made_ns)
        span = first_and_last(db, crossing.tool_id, made_ns)
        assert span is not None
        row = db.execute(
            "SELECT MAX(serviced_ns) FROM services WHERE tool_id = ? AND serviced_ns <= ?",
            (crossing.tool_id, made_ns),
        ).fetchone()
        serviced_ns = row[0]
        window_ns = made_ns - READ_WINDOW_DAYS * DAY_NS
        from_ns = -1 if serviced_ns is None else min(serviced_ns, window_ns)
        groups = grouped_runs(db, crossing.tool_id, calendar, from_ns, serviced_ns, made_ns)
    since = sum(group.intensity for group in groups if group.after_service)
    return Case(plant, crossing, ahead, made_ns, groups, calendar, span, serviced_ns, since)


@dataclass(frozen=True)
class Outcome:
    ahead_days: int
    dated: bool
    error_days: float  # forecast minus actual, production days (nan: no date)
    held: bool  # the 80 % interval held the crossing


def judge(case: Case, settings: ForecastSettings) -> Outcome:
    seen = tool_outlook(
        case.groups,
        case.calendar,
        case.span[0],
        case.span[1],
        case.serviced_ns,
        case.made_ns,
        settings=settings,
    )
    told = forecast(
        case.crossing.tool_id,
        seen.pace,
        seen.calendar,
        case.since_service,
        case.plant.threshold,
        case.made_ns,
        settings,
    )
    if told.state != "forecast" or told.due_ns is None:
        return Outcome(case.ahead_days, False, float("nan"), False)
    position = case.plant.calendar.position
    actual = position(case.crossing.crossed_ns)
    error = position(told.due_ns) - actual
    early = told.early_ns if told.early_ns is not None else told.due_ns
    held = early <= case.crossing.crossed_ns and (
        told.late_ns is None or case.crossing.crossed_ns <= told.late_ns
    )
    return Outcome(case.ahead_days, True, error, held)


def summary(outcomes: list[Outcome]) -> dict[int, dict[str, float]]:
    figures = {}
    for ahead in HORIZONS:
        chosen = [o for o in outcomes if o.ahead_days == ahead]
        dated = [o for o in chosen if o.dated]
        errors = np.array([o.error_days for o in dated])
        figures[ahead] = {
            "cases": len(chosen),
            "no date": len(chosen) - len(dated),
            "median |error|": float(np.median(np.abs(errors))) if dated else float("nan"),
            "p90 |error|": float(np.percentile(np.abs(errors), 90)) if dated else float("nan"),
            "mean error": float(errors.mean()) if dated else float("nan"),
            "held": float(np.mean([o.held for o in dated])) if dated else float("nan"),
        }
    return figures


def print_summary(title: str, figures: dict[int, dict[str, float]], everything: float) -> None:
    print(f"\n{title}")
    print("  ahead   cases  no date  median|err|  p90|err|  mean err  80% interval held")
    for ahead, row in figures.items():
        print(
            f"  {ahead:>3} d  {row['cases']:>6.0f}  {row['no date']:>7.0f}  "
            f"{row['median |error|']:>11.2f}  {row['p90 |error|']:>8.2f}  "
            f"{row['mean error']:>+8.2f}  {100 * row['held']:>16.1f} %"
        )
    print(f"  all horizons: the interval held {100 * everything:.1f} %")


def held_share(outcomes: list[Outcome]) -> float:
    dated = [o for o in outcomes if o.dated]
    return float(np.mean([o.held for o in dated])) if dated else float("nan")


def load(
    plants: tuple[tuple[str, int], ...], folder: Path, days: int | None
) -> tuple[list[Case], list[Case]]:
    cases: list[Case] = []
    early: list[Case] = []
    for shape_name, seed in plants:
        shape = SHAPES[shape_name]
        if days is not None:
            from dataclasses import replace

            shape = replace(shape, days=days)
        started = time.perf_counter()
        plant = simulate(shape, seed)
        path = folder / f"{shape_name}-{seed}.sqlite"
        write_ledger(plant, path)
        found, first_week = read_cases(plant, path)
        cases.extend(found)
        early.extend(first_week)
        print(
            f"plant {shape.name!r} seed {seed}: {plant.ended_ns.size} runs, "
            f"{len(plant.crossings)} crossings, {len(found)} cases "
            f"({time.perf_counter() - started:.1f} s)",
            file=sys.stderr,
        )
    return cases, early


def tune(cases: list[Case]) -> ForecastSettings:
    """The settings with the smallest median errors at 7 and 30 days, then the drift whose
    interval holds closest to 80 %."""
    best: tuple[float, ForecastSettings] | None = None
    for half_life, window in itertools.product((5.0, 7.0, 10.0, 14.0, 21.0), (28, 42, 56, 70, 98)):
        settings = ForecastSettings(window_days=window, half_life_days=half_life)
        figures = summary([judge(case, settings) for case in cases])
        score = figures[7]["median |error|"] + figures[30]["median |error|"] / 3
        if best is None or score < best[0]:
            best = (score, settings)
    assert best is not None
    chosen = best[1]
    closest: tuple[float, ForecastSettings] | None = None
    for drift in np.arange(0.0, 0.31, 0.02):
        settings = ForecastSettings(
            window_days=chosen.window_days, half_life_days=chosen.half_life_days, drift=float(drift)
        )
        held = held_share([judge(case, settings) for case in cases])
        if closest is None or abs(held - 0.8) < closest[0]:
            closest = (abs(held - 0.8), settings)
    assert closest is not None
    return closest[1]


def cost() -> None:
    """ms per counted run with and without the forecast, and one reading of every tool."""
    import statistics

    from services.recorder.wear_watch import WearWatch
    from shared.wear import CONTRACT_LIMITS, WearLedger
    from tests.support.factories import summary
    from tests.support.wear_plant import TWO_SHIFTS

    plant = simulate(TWO_SHIFTS, 31)
    counted, rounds = 300, 5
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "wear.sqlite"
        write_ledger(plant, path)
        tools = sorted({int(tool) for tool in plant.tool_id})
        start_ns = plant.calendar.time_at(max(plant.calendar.day_of_stretch) + 0.5)
        next_id = int(plant.run_id[-1]) + 1

        def per_run(watch: WearWatch) -> float:
            nonlocal next_id
            started = time.perf_counter()
            for index in range(counted):
                ended_ns = start_ns + (next_id - int(plant.run_id[-1])) * 1_000_000_000
                run = summary(
                    next_id,
                    station=plant.station_names[index % len(tools)],
                    tool_id=tools[index % len(tools)],
                    process_intensity=1.0e3,
                    events=4,
                    started_ns=ended_ns - 3_000_000_000,
                    ended_ns=ended_ns,
                )
                watch.on_summary(run, ended_ns)
                next_id += 1
            return (time.perf_counter() - started) * 1e3 / counted

        limits = lambda _summary: CONTRACT_LIMITS  # noqa: E731
        plain = WearWatch(path, plant.threshold, lambda _alert: None, limits)
        forecasting = WearWatch(path, plant.threshold, lambda _alert: None, limits, [7.0, 1.0])
        without, with_forecast = [], []
        for _round in range(rounds):
            without.append(per_run(plain))
            with_forecast.append(per_run(forecasting))
        plain.close()
        forecasting.close()
        started = time.perf_counter()
        with WearLedger(path, read_only=True) as ledger:
            read = ledger.tools()
        reading_s = time.perf_counter() - started
    print(
        f"\nper counted run ({plant.ended_ns.size} runs in the ledger, {len(tools)} tools): "
        f"{statistics.median(without):.3f} ms without the forecast, "
        f"{statistics.median(with_forecast):.3f} ms with it (its pace read once a day and tool, "
        f"included); every tool's line with its outlook ({len(read)} tools): "
        f"{reading_s * 1e3:.0f} ms"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tune", action="store_true", help="search the settings first")
    parser.add_argument("--quick", action="store_true", help="120 days per plant, not 240")
    parser.add_argument("--cost", action="store_true", help="only the recorder's cost per run")
    args = parser.parse_args()
    if args.cost:
        cost()
        return 0
    days = 120 if args.quick else None
    shipped = ForecastSettings()
    with tempfile.TemporaryDirectory() as folder:
        if args.tune:
            cases, _ = load(TUNING, Path(folder), days)
            chosen = tune(cases)
            print(f"tuned on {len(cases)} cases: {chosen}")
            outcomes = [judge(case, chosen) for case in cases]
            print_summary("tuning plants, tuned settings", summary(outcomes), held_share(outcomes))
        cases, early = load(JUDGING, Path(folder), days)
    print(f"\nshipped settings: {shipped}")
    outcomes = [judge(case, shipped) for case in cases]
    print_summary(
        "judging plants (other seeds, and a shape never tuned on)",
        summary(outcomes),
        held_share(outcomes),
    )
    for shape_name in ("two", "three", "one"):
        chosen_cases = [case for case in cases if case.plant.shape.name == SHAPES[shape_name].name]
        part = [judge(case, shipped) for case in chosen_cases]
        print_summary(f"  of which {SHAPES[shape_name].name}", summary(part), held_share(part))
    dated = sum(judge(case, shipped).dated for case in early)
    print(f"\na tool's first week: {dated} of {len(early)} forecasts gave a date (should be 0)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
