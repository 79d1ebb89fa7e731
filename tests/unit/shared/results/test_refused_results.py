"""One rule for what a result is, at the store's door: a tightening whose figures cannot be a
measurement (:mod:`shared.quality.plausible_result`) is never a result to any reader of the
store (``results``, ``report``, OPC UA, the part search). Whatever writes it (the recorder,
``results rebuild``, an import read by either) has it kept aside, whole, and named in the
words ``report`` uses; a store an older boltwatch filled with such rows is cleared of them
at its first open; the retention policy counts a refused result as stored."""

from __future__ import annotations

import dataclasses
from typing import Any

from shared.contract import JudgedFigure, ResultStep, TighteningResult
from shared.quality import implausible, refusal_line
from shared.results import (
    ResultsQuery,
    ResultsStore,
    StoreTarget,
    program_columns,
    stored_result,
)
from tests.support import factories
from tests.support.old_results_store import old_store

SECOND_NS = 1_000_000_000
#: one result beyond each bound, and what its line says
ABSURD: dict[str, dict[str, Any]] = {
    "final torque 1e+308 Nm": {"final_torque_nm": JudgedFigure(1e308, 180.0, 240.0, "high")},
    "final angle window max 2e+07 deg": {"final_angle_deg": JudgedFigure(50.0, 35.0, 2e7, "ok")},
    "final preload -2e+09 N": {"final_force_n": JudgedFigure(-2e9, None, None, "low")},
    "2000000 stick-slip events": {"events": 2_000_000},
    "process intensity -1": {"process_intensity": -1.0},
}


def _good(run_id: int) -> TighteningResult:
    return factories.result(run_id, time_ns=factories.T0 + run_id * SECOND_NS)


def _absurd() -> list[TighteningResult]:
    return [
        factories.result(
            10 + n,
            time_ns=factories.T0 + (10 + n) * SECOND_NS,
            steps=[ResultStep("Tightening", "TF Torque", 25.0, 1e308, "NOK")],
            **changes,
        )
        for n, changes in enumerate(ABSURD.values())
    ]


def _line(result: TighteningResult) -> str:
    why = implausible(result)
    assert why is not None
    return refusal_line(result.station, result.run_id, result.tool_id, why)


def test_a_result_that_cannot_be_a_measurement_is_kept_aside_and_named(
    target: StoreTarget,
) -> None:
    good, absurd = [_good(n) for n in range(1, 4)], _absurd()
    refused: list[str] = []
    with ResultsStore(target) as store:
        new = store.add([stored_result(r, "A", None, None, 1) for r in good + absurd], refused)
        assert new == len(good)
        assert refused == [_line(result) for result in absurd]
        for why, line in zip(ABSURD, refused, strict=True):
            assert why in line
        everything = ResultsQuery(limit=None, oldest_first=True)
        assert [stored.result for stored in store.find(everything)] == good
        assert store.count(everything) == len(good)
        assert store.keys(ResultsQuery(run_id=10, stations=["st1"])) == []
        assert store.refused(everything) == refused  # what a reader names, in the same words
        assert store.refused(ResultsQuery(since_ns=absurd[-1].time_ns)) == refused[-1:]
        # the retention policy: a refused result is in the store, its recording may go
        keys = [("st1", result.run_id) for result in good + absurd]
        assert set(store.verdicts(keys)) == set(keys)

        # stored again (a rebuild reads the file again): named again, nothing new
        again: list[str] = []
        assert store.add([stored_result(absurd[0], "A", None, None, 2)], again) == 0
        assert again == refused[:1]
        # the first stored stays, refused or not: a good result of a refused run stays out
        assert store.add([stored_result(_good(10), "A", None, None, 3)]) == 0
        assert store.count(everything) == len(good)
        assert store.add([stored_result(absurd[1], "A", None, None, 3)], []) == 0
        # in one batch too: a run's absurd tightening, then a result of the same run
        late = dataclasses.replace(absurd[0], run_id=30)
        assert store.add([stored_result(r, "A", None, None, 4) for r in (late, _good(30))]) == 0
        assert store.count(everything) == len(good)
        assert store.refused(ResultsQuery(run_id=30, stations=["st1"])) == [_line(late)]
        assert store.refused(ResultsQuery(run_id=1, stations=["st1"])) == []
        assert store.find(ResultsQuery(run_id=1, stations=["st1"]))[0].result == good[0]


def test_a_store_an_older_boltwatch_filled_with_absurd_results_is_cleared_at_first_open(
    target: StoreTarget,
) -> None:
    """A store of version 3 (``results rebuild`` stored every result then): the first open,
    a reader's too, moves the rows no reader may count, with their steps, aside."""
    good, absurd = [_good(n) for n in range(1, 4)], _absurd()
    old_store(target, [stored_result(result, "A", None, None, 1) for result in good + absurd], 3)
    with ResultsStore(target, create=False) as store:
        assert store.migrated_from == 3
        everything = ResultsQuery(limit=None, oldest_first=True)
        assert [stored.result for stored in store.find(everything)] == good
        assert store.refused(everything) == [_line(result) for result in absurd]
        keys = [("st1", result.run_id) for result in good + absurd]
        assert set(store.verdicts(keys)) == set(keys)


def test_every_reader_of_the_store_counts_the_same(target: StoreTarget) -> None:
    """``find``, ``count``, ``keys`` (``results``, OPC UA, the part search) and the report's
    columns agree on what is a result and name the same refused ones."""
    good, absurd = [_good(n) for n in range(1, 7)], _absurd()
    with ResultsStore(target) as store:
        store.add([stored_result(r, "A", None, None, 1) for r in good + absurd])
        query = ResultsQuery(stations=["st1"], limit=None, oldest_first=True)
        columns = program_columns(store, query)
        (program,) = columns.programs
        assert program.runs == store.count(query) == len(store.keys(query)) == len(good)
        assert columns.refused == store.refused(query) == [_line(r) for r in absurd]
