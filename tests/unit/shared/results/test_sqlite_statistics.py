"""The SQLite store's planner statistics: written by its writer from its rows, again when the
rows have doubled, and what they change: a month of a line read by the time index."""

from __future__ import annotations

import threading
from pathlib import Path

import pytest

from shared.errors import StoreError
from shared.results import (
    ResultsDatabase,
    ResultsQuery,
    ResultsStore,
    StoreTarget,
    results_store,
    stored_result,
)
from shared.results.sqlite_statistics import FEWEST_ROWS, keep_statistics, statistics_rows
from tests.support import factories

STATIONS = ("st1", "st2", "st3")
SECOND_NS = 1_000_000_000
MINUTE_NS = 60 * SECOND_NS


def _add(store: ResultsStore, first_run: int, runs: int) -> None:
    store.add(
        [
            stored_result(
                factories.result(
                    run_id,
                    station=station,
                    time_ns=factories.T0 + run_id * MINUTE_NS + number * SECOND_NS,
                    part_id=f"VIN{run_id // 4}",
                    program_id=run_id % 2,
                ),
                "A",
                f"/rec/{station}_run{run_id}.mcap",
                "box",
                1,
            )
            for run_id in range(first_run, first_run + runs)
            for number, station in enumerate(STATIONS)
        ]
    )


def _stat1(store: ResultsStore) -> dict[str, str]:
    rows = store.database.rows("SELECT idx, stat FROM sqlite_stat1 WHERE tbl = 'tightenings'")
    return dict(rows)


def _month_plan(target: StoreTarget) -> str:
    """How a new connection reads a month of the three stations for a report (EXPLAIN QUERY
    PLAN): every row of the range, in the order the runs ended."""
    since_ns = factories.T0 + 100 * MINUTE_NS
    query = ResultsQuery(
        stations=STATIONS,
        since_ns=since_ns,
        until_ns=since_ns + 300 * MINUTE_NS,
        limit=None,
        oldest_first=True,
    )
    where, parameters = query.where()
    with ResultsStore(target, create=False) as reader:
        plan = reader.database.rows(
            f"EXPLAIN QUERY PLAN SELECT torque_nm FROM tightenings{where}{query.order()}",
            parameters,
        )
    return " ".join(str(row[-1]) for row in plan)


def test_the_writer_writes_statistics_of_the_rows_and_a_month_is_read_by_time(
    tmp_path: Path,
) -> None:
    target = StoreTarget(sqlite_path=tmp_path / "results.sqlite")
    with ResultsStore(target) as store:
        _add(store, 0, 300)  # 900 rows: too few for statistics
        assert statistics_rows(store.database) == 0
    assert "tightenings_by_station" in _month_plan(target)  # SQLite's guesses
    with ResultsStore(target) as store:
        _add(store, 300, 200)
        assert keep_statistics(store.database) == 1500  # its rows at the writer's open
    with ResultsStore(target) as store:  # a writer's open: its rows have not doubled
        assert statistics_rows(store.database) == 1500
        stat = _stat1(store)
    assert stat["tightenings_by_station"] == "1500 500 1"  # three stations
    assert stat["tightenings_by_line"] == "1500 1500 1"
    assert stat["tightenings_by_program"] == "1500 750 1"
    assert stat["tightenings_by_time"] == "1500 1"
    assert stat["sqlite_autoindex_tightenings_1"] == "1500 500 1"
    assert stat["tightenings_by_part"] == "1500 12 1"  # a part: four runs of three stations
    assert "tightenings_by_time" in _month_plan(target)


def test_the_statistics_are_written_again_when_the_rows_have_doubled(tmp_path: Path) -> None:
    target = StoreTarget(sqlite_path=tmp_path / "results.sqlite")
    with ResultsStore(target) as store:
        _add(store, 0, FEWEST_ROWS // 3 + 1)  # the writer's adds cross FEWEST_ROWS
        first = statistics_rows(store.database)
        assert first == 3 * (FEWEST_ROWS // 3 + 1)
        _add(store, 1000, first // 3 - 1)
        assert statistics_rows(store.database) == first  # not doubled yet
        _add(store, 2000, 1)
        assert statistics_rows(store.database) == 2 * first


def test_postgresql_keeps_its_own(postgres_url: str) -> None:
    with ResultsStore(StoreTarget(postgres_url=postgres_url)) as store:
        _add(store, 0, 400)
        assert keep_statistics(store.database) == 0


def test_an_index_on_an_expression_is_left_to_sqlite_and_a_new_index_is_described(
    tmp_path: Path,
) -> None:
    target = StoreTarget(sqlite_path=tmp_path / "results.sqlite")
    with ResultsStore(target) as store:
        _add(store, 0, 500)
        with store.database.transaction():
            store.database.execute("CREATE INDEX by_lower_part ON tightenings (lower(part_id))")
            store.database.execute('CREATE INDEX "by ""tool"" id" ON tightenings (tool_id)')
        assert keep_statistics(store.database) == 1500  # not doubled, but an index is new
        stat = _stat1(store)
    assert stat['by "tool" id'] == "1500 1500"  # one tool; the index's one column
    assert "by_lower_part" not in stat


def test_statistics_that_cannot_be_written_do_not_keep_a_result_from_the_store(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    def refused(database: object) -> int:
        raise StoreError("results store: database is locked")

    monkeypatch.setattr(results_store, "keep_statistics", refused)
    target = StoreTarget(sqlite_path=tmp_path / "results.sqlite")
    with ResultsStore(target) as store:  # the writer's open tries them too
        _add(store, 0, FEWEST_ROWS // 3 + 1)
        assert store.count(ResultsQuery()) == 3 * (FEWEST_ROWS // 3 + 1)
    assert "planner statistics not written: results store: database is locked" in caplog.text


def _without_statistics(target: StoreTarget) -> None:
    """The store as one no writer of this boltwatch has opened since it filled up: a
    ``results rebuild`` of an older boltwatch, a copy of a line's store (no ``sqlite_stat1``)."""
    with ResultsStore(target) as store, store.database.transaction():
        store.database.execute("DELETE FROM sqlite_stat1")
    with ResultsDatabase(target) as database:
        assert statistics_rows(database) == 0


def test_a_store_only_readers_open_gets_its_statistics_from_the_first(tmp_path: Path) -> None:
    target = StoreTarget(sqlite_path=tmp_path / "results.sqlite")
    with ResultsStore(target) as store:
        _add(store, 0, 500)
    _without_statistics(target)
    assert "tightenings_by_time" in _month_plan(target)  # the reader's own plan, already
    with ResultsDatabase(target) as database:
        assert statistics_rows(database) == 1500  # and every reader's after it


def test_a_reader_waits_for_no_writer_to_write_statistics(tmp_path: Path) -> None:
    """A writer holds the store's lock (a recorder's transaction, a migration): the reader
    answers at once, planning with SQLite's guesses; the next reader writes them."""
    target = StoreTarget(sqlite_path=tmp_path / "results.sqlite")
    with ResultsStore(target) as store:
        _add(store, 0, 500)
    _without_statistics(target)
    plans: list[str] = []
    with ResultsDatabase(target) as writer, writer.transaction(lock=True):
        reader = threading.Thread(target=lambda: plans.append(_month_plan(target)), daemon=True)
        reader.start()
        reader.join(5.0)
        assert len(plans) == 1 and "tightenings_by_station" in plans[0]
    with ResultsDatabase(target) as database:
        assert statistics_rows(database) == 0
    assert "tightenings_by_time" in _month_plan(target)
