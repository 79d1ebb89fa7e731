"""The store's versions: a new store is made whole, an older one migrated with nothing
lost (a store of version 1, before the plant model, of version 2, before the part's
source, and of version 4, before a final stage's pulses, among them), a newer one refused, a
reader of a current one takes no lock, writers starting together migrate once, a damaged
file is named and left as it is."""

from __future__ import annotations

import csv
import io
import threading
from pathlib import Path

import pytest

from shared.contract import ResultStep
from shared.errors import StoreError
from shared.results import (
    MIGRATIONS,
    SCHEMA_VERSION,
    ResultsDatabase,
    ResultsQuery,
    ResultsStore,
    StoreTarget,
    migrate,
    stored_result,
    version_of,
)
from shared.results.results_table import format_csv, format_table
from tests.support import factories
from tests.support.old_results_store import version_1_store, version_2_store, version_4_store

#: a later version, as the next boltwatch would bring one: a column added
NEXT_VERSION = (*MIGRATIONS, ("ALTER TABLE tightenings ADD COLUMN operator TEXT",))


def test_a_new_store_is_made_at_the_current_version(target: StoreTarget) -> None:
    with ResultsStore(target) as store:
        assert (store.migrated_from, store.version) == (0, SCHEMA_VERSION)
    with ResultsStore(target) as store:  # opened again: nothing to do
        assert store.migrated_from == SCHEMA_VERSION


def test_an_older_store_is_migrated_and_keeps_its_results(target: StoreTarget) -> None:
    with ResultsStore(target) as store:
        store.add([stored_result(factories.result(run), "A", None, None, 1) for run in (1, 2)])
    with ResultsDatabase(target) as database:
        assert migrate(database, NEXT_VERSION) == SCHEMA_VERSION
        assert version_of(database) == SCHEMA_VERSION + 1
        with database.transaction():
            assert database.rows("SELECT run_id, operator FROM tightenings ORDER BY run_id") == [
                (1, None),
                (2, None),
            ]


def test_a_version_1_store_is_migrated_at_start_with_every_row_kept(target: StoreTarget) -> None:
    """Version 2 (the plant model) adds ``plant`` and ``station_name`` to a store of
    version 1 with rows: the first writer to open it (the recorder at start) migrates it;
    each row and its steps are as stored, the new columns '' (none named); new rows carry
    theirs and ``--plant`` finds them by its index."""
    steps = [ResultStep("Rundown", "TF Angle", 720.0, 731.5, "OK")]
    old = [
        stored_result(
            factories.result(run, part_id=f"VIN{run}", source="controller", steps=steps),
            "A",
            f"/rec/st1_run{run}.mcap",
            "box",
            run,
        )
        for run in (1, 2)
    ]
    version_1_store(target, old)
    with ResultsStore(target) as store:
        assert (store.migrated_from, store.version) == (1, SCHEMA_VERSION)
        assert store.find(ResultsQuery(oldest_first=True)) == old
        assert {(s.plant, s.station_name) for s in old} == {("", "")}
        new = stored_result(
            factories.result(3), "A", None, None, 3, plant="North", station_name="Nuts"
        )
        store.add([new])
        assert store.find(ResultsQuery(plant="North")) == [new]
        assert store.count(ResultsQuery(plant="")) == 2
    with ResultsDatabase(target) as database, database.transaction():
        indexes = database.rows(
            "SELECT name FROM sqlite_master WHERE type = 'index'"
            if database.dialect == "sqlite"
            else "SELECT indexname FROM pg_indexes WHERE tablename = 'tightenings'"
        )
    assert ("tightenings_by_plant",) in indexes


def test_a_version_2_store_is_migrated_at_start_and_its_parts_source_is_not_said(
    target: StoreTarget,
) -> None:
    """Version 3 adds ``part_source`` (where the part of a live run came from: scanned, or
    restored from the line when the predictor started): the rows stored before say nothing
    (None), as a result recorded before says nothing; new rows keep theirs."""
    old = [
        stored_result(factories.result(run, part_id=f"P{run}"), "A", f"/rec/{run}.mcap", "box", run)
        for run in (1, 2)
    ]
    version_2_store(target, old)
    with ResultsStore(target) as store:
        assert (store.migrated_from, store.version) == (2, SCHEMA_VERSION)
        kept = store.find(ResultsQuery(oldest_first=True))
        assert kept == old and {s.result.part_source for s in kept} == {None}
        restored = factories.result(3, part_id="P2", part_source="restored")
        store.add([stored_result(restored, "A", None, None, 3)])
        newest = store.find(ResultsQuery(part_id="P2"))[0]  # newest first
        assert newest.result == restored


def test_a_store_of_a_newer_boltwatch_is_not_written_into(target: StoreTarget) -> None:
    with ResultsStore(target) as store:
        store.add([stored_result(factories.result(1), "A", None, None, 1)])
    with ResultsDatabase(target) as database, database.transaction():
        database.execute("UPDATE store_version SET version = ?", (SCHEMA_VERSION + 5,))
    newer = rf"version {SCHEMA_VERSION + 5} is newer than this boltwatch's {SCHEMA_VERSION}"
    with pytest.raises(StoreError, match=newer):
        ResultsStore(target)
    with ResultsDatabase(target) as database:
        assert version_of(database) == SCHEMA_VERSION + 5
        with database.transaction():
            assert database.rows("SELECT COUNT(*) FROM tightenings") == [(1,)]


def test_a_reader_of_a_current_store_waits_for_no_writer(target: StoreTarget) -> None:
    with ResultsStore(target) as store:
        store.add([stored_result(factories.result(1), "A", None, None, 1)])
    found: list[int] = []

    def read() -> None:
        with ResultsStore(target, create=False) as reader:
            found.append(len(reader.find(ResultsQuery())))

    # a writer holds the store's lock (a recorder migrating, a rebuild writing)
    with ResultsDatabase(target) as writer, writer.transaction(lock=True):
        reader = threading.Thread(target=read, daemon=True)
        reader.start()
        reader.join(5.0)
        assert found == [1]


def test_writers_starting_together_migrate_once(target: StoreTarget) -> None:
    errors: list[BaseException] = []
    start = threading.Barrier(4)

    def open_store() -> None:
        start.wait()
        try:
            with ResultsStore(target) as store:
                store.add([stored_result(factories.result(1), "A", None, None, 1)])
        except BaseException as err:  # the test says which, below
            errors.append(err)

    threads = [threading.Thread(target=open_store) for _ in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert errors == []
    with ResultsStore(target) as store:
        assert store.count(ResultsQuery()) == 1


def test_a_damaged_file_is_named_and_left_as_it_is(tmp_path: Path) -> None:
    path = tmp_path / "results.sqlite"
    damage = b"not a database at all " * 100
    path.write_bytes(damage)
    with pytest.raises(StoreError, match=rf"results store {path}: .*not a database"):
        ResultsStore(StoreTarget(sqlite_path=path))
    assert path.read_bytes() == damage


def test_an_unreachable_server_is_one_line_without_its_password() -> None:
    target = StoreTarget(postgres_url="postgresql://boltwatch:secret@127.0.0.1:1/results")
    with pytest.raises(StoreError) as raised:
        ResultsStore(target)
    text = str(raised.value)
    assert "secret" not in text and "\n" not in text
    assert text.startswith("results store postgresql://boltwatch:***@127.0.0.1:1/results")


def test_a_version_4_store_is_migrated_at_start_and_keeps_a_final_stages_pulses(
    target: StoreTarget,
) -> None:
    """Version 5 adds ``pulses`` (a final stage's pulses back to the target): the rows stored
    before say nothing (None, as a run without a final stage); new rows keep theirs, found by
    the table and the CSV."""
    old = [
        stored_result(factories.result(run), "A", f"/rec/{run}.mcap", "box", run) for run in (1, 2)
    ]
    version_4_store(target, old)
    with ResultsStore(target) as store:
        assert (store.migrated_from, store.version) == (4, SCHEMA_VERSION)
        kept = store.find(ResultsQuery(oldest_first=True))
        assert kept == old and {s.result.pulses for s in kept} == {None}
        staged = factories.result(3, pulses=1, stop_reason="target_reached")
        store.add([stored_result(staged, "A", None, None, 3)])
        newest = store.find(ResultsQuery(oldest_first=False))[0]
        assert newest.result == staged
    assert "target_reached+pulse" in format_table([newest])
    (row,) = csv.DictReader(io.StringIO(format_csv([newest])))
    assert row["pulses"] == "1"
