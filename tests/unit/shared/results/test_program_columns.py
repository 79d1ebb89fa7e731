"""A report's columns from the store are the columns of the results themselves: the same
statistics from ``program_columns`` (a few statements) as from ``program_statistics`` over
the results read one by one, on SQLite and PostgreSQL, whatever the program ids; a
tightening whose figures cannot be a measurement is left out of them and named."""

from __future__ import annotations

from typing import Any

import numpy as np

from shared.contract import JudgedFigure, TighteningResult
from shared.quality import ProgramStatistics, program_statistics, statistics_of
from shared.results import (
    ResultsQuery,
    ResultsStore,
    StoreTarget,
    program_columns,
    stored_result,
)
from tests.support import factories

SECOND_NS = 1_000_000_000
RUNS = 120


def _results() -> list[TighteningResult]:
    """Two programs on three stations and four tools, in the order the runs ended: values
    missing now and then, NOKs with several reasons, every stop reason and none, a torque
    window and a program name changed halfway, runs ending at the same time, program 2's
    second half run in a final stage, now and then with a pulse."""
    rng = np.random.default_rng(5)
    results = []
    for n in range(RUNS):
        program = 1 + n % 2
        changed = n >= RUNS // 2
        torque = None if n % 17 == 0 else float(rng.normal(210.0, 12.0))
        force = None if n % 11 == 0 else float(rng.normal(56000.0, 1500.0))
        window = (185.0, 235.0) if changed and program == 1 else (180.0, 240.0)
        reasons = []
        if torque is not None and not window[0] <= torque <= window[1]:
            reasons.append(f"torque {'low' if torque < window[0] else 'high'}: {torque:.1f} Nm")
        if force is not None and force < 54000.0:
            reasons.append(f"preload low: {force:.0f} N, window 54000 to 59000 N")
        results.append(
            factories.result(
                n + 1,
                station=f"st{1 + n % 3}",
                tool_id=7 + n % 4,
                program_id=program,
                program_name=f"P{program}{' v2' if changed else ''}",
                time_ns=factories.T0 + (n // 2) * SECOND_NS,  # two runs end at each time
                final_torque_nm=JudgedFigure(torque, *window, "ok"),
                final_angle_deg=JudgedFigure(float(rng.normal(47.0, 5.0)), 35.0, None, "ok"),
                final_force_n=JudgedFigure(force, 54000.0, 59000.0, "ok"),
                result="NOK" if reasons else "OK",
                nok_reasons="; ".join(reasons),
                stop_reason=(None, "plateau_closest", "target_reached")[n % 3],
                events=None if n % 13 == 0 else int(rng.integers(30, 45)),
                process_intensity=None if n % 7 == 0 else float(rng.normal(1e6, 4e4)),
                pulses=(n % 5 == 0) + (n % 15 == 0) if changed and program == 2 else None,
            )
        )
    results.sort(key=lambda result: (result.time_ns, result.station, result.run_id))
    return results


def _same(stored: ProgramStatistics, read: ProgramStatistics) -> None:
    assert (stored.program_id, stored.program_name) == (read.program_id, read.program_name)
    assert (stored.runs, stored.noks) == (read.runs, read.noks)
    assert stored.nok_reasons == read.nok_reasons and stored.stop_reasons == read.stop_reasons
    assert stored.events_per_run == read.events_per_run
    assert stored.window_changes == read.window_changes
    assert (stored.stations, stored.tools) == (read.stations, read.tools)
    assert (stored.staged_runs, stored.pulsed_runs) == (read.staged_runs, read.pulsed_runs)
    for mine, theirs in zip(stored.figures, read.figures, strict=True):
        assert mine.key == theirs.key
        np.testing.assert_array_equal(mine.values, theirs.values)
        assert mine.capability == theirs.capability
        assert (mine.chart is None) == (theirs.chart is None)
        if mine.chart is not None and theirs.chart is not None:
            np.testing.assert_array_equal(mine.chart.means, theirs.chart.means)


def test_the_stores_columns_give_the_statistics_of_the_results(target: StoreTarget) -> None:
    results = _results()
    with ResultsStore(target) as store:
        store.add([stored_result(result, "A", None, None, 1) for result in results])
        stored = [
            statistics_of(c, 5) for c in program_columns(store, ResultsQuery(limit=3)).programs
        ]
        query = ResultsQuery(stations=["st1", "st2"], since_ns=factories.T0 + 10 * SECOND_NS)
        some = [statistics_of(c, 5) for c in program_columns(store, query).programs]
        assert program_columns(store, ResultsQuery(part_id="none such")).programs == []
    read = program_statistics(results, 5)
    assert [program.runs for program in stored] == [RUNS // 2, RUNS // 2]
    assert any(program.window_changes for program in stored), "the torque window changed"
    assert all(program.nok_reasons for program in stored), "some runs must be NOK"
    assert [(p.staged_runs, p.pulsed_runs) for p in stored] == [(0, 0), (RUNS // 4, 6)]
    for mine, theirs in zip(stored, read, strict=True):
        _same(mine, theirs)
    kept = [
        result
        for result in results
        if result.station in ("st1", "st2") and result.time_ns >= query.since_ns  # type: ignore[operator]
    ]
    for mine, theirs in zip(some, program_statistics(kept, 5), strict=True):
        _same(mine, theirs)


def test_programs_a_float_cannot_tell_apart_are_two_programs(target: StoreTarget) -> None:
    """Program ids are the contract's 64-bit ids (a controller's, imported): 2**53 and
    2**53 + 1 are one number as a float, and two programs with their own runs in the store
    as in the results."""
    results = [
        factories.result(n, time_ns=factories.T0 + n * SECOND_NS, program_id=2**53 + n % 2)
        for n in range(1, 7)
    ]
    with ResultsStore(target) as store:
        store.add([stored_result(result, "A", None, None, 1) for result in results])
        stored = [statistics_of(c, 5) for c in program_columns(store, ResultsQuery()).programs]
    read = program_statistics(results, 5)
    assert [(p.program_id, p.runs) for p in stored] == [(2**53, 3), (2**53 + 1, 3)]
    for mine, theirs in zip(stored, read, strict=True):
        _same(mine, theirs)


def test_tightenings_that_cannot_be_a_measurement_are_left_out_and_named(
    target: StoreTarget,
) -> None:
    absurd: dict[str, dict[str, Any]] = {
        "final torque 1e+308 Nm": {"final_torque_nm": JudgedFigure(1e308, 180.0, 240.0, "high")},
        "final torque -1e+308 Nm": {"final_torque_nm": JudgedFigure(-1e308, None, None, "low")},
        "final preload window max 1e+300 N": {
            "final_force_n": JudgedFigure(55e3, 53e3, 1e300, "ok")
        },
        "2000000 stick-slip events": {"events": 2_000_000},
        "process intensity -1": {"process_intensity": -1.0},
    }
    good = [factories.result(n, time_ns=factories.T0 + n * SECOND_NS) for n in range(1, 7)]
    bad = [
        factories.result(10 + n, time_ns=factories.T0 + (10 + n) * SECOND_NS, **changes)
        for n, changes in enumerate(absurd.values())
    ]
    with ResultsStore(target) as store:
        store.add([stored_result(result, "A", None, None, 1) for result in good + bad])
        read = program_columns(store, ResultsQuery())
    (columns,), lines = read.programs, read.refused
    assert columns.runs == len(good) and float(columns.values["torque"].max()) < 1e6
    # nothing of them counted: not their stop reasons, not the window of 1e300 N
    assert sum(columns.stop_reasons.values()) == len(good)
    assert columns.window_counts["preload"] == 1 and columns.latest_windows["preload"][1] == 59e3
    assert len(lines) == len(absurd)
    for line, (why, result) in zip(lines, zip(absurd, bad, strict=True), strict=True):
        assert line.startswith(f"station st1 run {result.run_id} (tool 7): {why}"), line


def test_a_multi_spindle_programs_spindles_each_have_their_statistics(target: StoreTarget) -> None:
    """Four spindles of one program, spindle 3 drifting high: the program's statistics over
    every run, then each spindle's own, the same from the store as from the results; the
    drifting spindle's Cpk is the low one."""
    rng = np.random.default_rng(8)
    results = []
    for cycle in range(30):
        for spindle in (1, 2, 3, 4):
            drift = 1.5 * cycle if spindle == 3 else 0.0
            torque = float(rng.normal(205.0 + drift, 4.0))
            results.append(
                factories.result(
                    100 + 4 * cycle + spindle,
                    time_ns=factories.T0 + cycle * SECOND_NS + spindle,
                    tool_id=6 + spindle,
                    spindle=spindle,
                    sync_id=100 + 4 * cycle + 1,
                    final_torque_nm=JudgedFigure(torque, 180.0, 240.0, "ok"),
                    result="OK" if torque <= 240.0 else "NOK",
                    nok_reasons="" if torque <= 240.0 else f"torque high: {torque:.1f} Nm",
                )
            )
    with ResultsStore(target) as store:
        store.add([stored_result(result, "A", None, None, 1) for result in results])
        stored = [statistics_of(c, 5) for c in program_columns(store, ResultsQuery()).programs]
    read = program_statistics(results, 5)
    assert [(p.program_id, p.spindle, p.runs) for p in stored] == [
        (1, None, 120), (1, 1, 30), (1, 2, 30), (1, 3, 30), (1, 4, 30),
    ]  # fmt: skip
    for mine, theirs in zip(stored, read, strict=True):
        assert mine.spindle == theirs.spindle
        _same(mine, theirs)
    cpks = {p.spindle: p.figures[0].capability.cpk for p in stored}
    assert min(cpks, key=lambda spindle: cpks[spindle] or 0.0) == 3
    assert [p.tools for p in stored[1:]] == [[7], [8], [9], [10]]
