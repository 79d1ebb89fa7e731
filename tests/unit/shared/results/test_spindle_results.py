"""Multi-spindle stations in the results store: version 6 adds each tightening's spindle and
sync id (in both tables of tightenings) and the cycles' common results, with every row of a
version 5 store kept; a part's cycle is found whole, each run with its cycle, whichever of
the two was stored first; a single-spindle station's store reads as it did."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from services.cli.main import main
from shared.contract import CycleResult, CycleSpindle, JudgedFigure, Verdict
from shared.results import ResultsDatabase, ResultsQuery, ResultsStore, StoreTarget, stored_result
from shared.results.results_table import format_csv, format_json, format_table
from tests.support import factories
from tests.support.old_results_store import columns_of, version_5_store
from tests.support.paths import REPO

SINGLE_SPINDLE = REPO / "tests" / "data" / "single-spindle"


def cycle_of(sync_id: int, runs: dict[int, Verdict | None], part: str = "P7") -> CycleResult:
    """The common result of a cycle whose spindle k ran ``runs[k]`` (None: no result)."""
    verdicts = list(runs.values())
    bad = [f"spindle {k} {v or 'no result'}" for k, v in runs.items() if v != "OK"]
    return CycleResult(
        station="st1",
        sync_id=sync_id,
        time_ns=factories.T0,
        part_id=part,
        program_id=1,
        result="OK" if all(v == "OK" for v in verdicts) else "NOK",
        nok_reasons="; ".join(bad),
        source="predictor",
        spindles=[
            CycleSpindle(k, None if v is None else sync_id + k - 1, v) for k, v in runs.items()
        ],
    )


def spindle_results(sync_id: int, spindles: int, part: str = "P7") -> list:
    return [
        stored_result(
            factories.result(
                sync_id + k - 1, part_id=part, spindle=k, sync_id=sync_id, tool_id=7 + k - 1
            ),
            "A",
            f"/rec/st1_run{sync_id}.mcap",
            "box",
            1,
        )
        for k in range(1, spindles + 1)
    ]


def test_a_version_5_store_is_migrated_with_every_row_of_both_tables_kept(
    target: StoreTarget,
) -> None:
    old = [
        stored_result(factories.result(run, part_id=f"P{run}", pulses=1), "A", None, None, run)
        for run in (1, 2)
    ]
    version_5_store(target, old)
    absurd = stored_result(
        factories.result(3, final_force_n=JudgedFigure(1e30, None, None, "not_judged")),
        "A",
        None,
        None,
        3,
    )
    columns = columns_of(5)
    from shared.results.results_schema import TIGHTENING_COLUMNS
    from shared.results.stored_result import to_row

    row = dict(zip(TIGHTENING_COLUMNS, to_row(absurd), strict=True))
    with ResultsDatabase(target) as database, database.transaction():
        database.execute(
            f"INSERT INTO refused_tightenings ({', '.join(columns)}) "
            f"VALUES ({', '.join('?' * len(columns))})",
            [row[column] for column in columns],
        )
    with ResultsStore(target) as store:
        assert store.migrated_from == 5
        kept = store.find(ResultsQuery(oldest_first=True))
        assert kept == old
        assert {(s.result.spindle, s.result.sync_id, s.cycle) for s in kept} == {(None, None, None)}
        assert len(store.refused(ResultsQuery())) == 1
        # the refused table has the new columns too: a spindle's absurd result is kept aside
        store.add(
            [
                stored_result(
                    factories.result(
                        9,
                        spindle=2,
                        sync_id=8,
                        final_force_n=JudgedFigure(1e30, None, None, "not_judged"),
                    ),
                    "A",
                    None,
                    None,
                    9,
                )
            ]
        )
        assert len(store.refused(ResultsQuery())) == 2


def test_a_parts_cycle_is_found_whole_with_its_common_result(target: StoreTarget) -> None:
    with ResultsStore(target) as store:
        store.add([stored_result(factories.result(1, part_id="P1"), "A", None, None, 1)])
        # the cycle's result before two of its runs' results (a spool's resend): either order
        cycle = cycle_of(100, {1: "OK", 2: "OK", 3: "NOK", 4: "OK"})
        results = spindle_results(100, 4)
        store.add(results[:2])
        assert store.add_cycles([cycle], 5) == 4
        assert store.add_cycles([cycle], 6) == 0  # stored once
        store.add(results[2:])
        found = store.find(ResultsQuery(part_id="P7", oldest_first=True))
    assert [s.result.spindle for s in found] == [1, 2, 3, 4]
    assert {s.result.sync_id for s in found} == {100}
    cycles = [s.cycle for s in found if s.cycle is not None]
    assert len(cycles) == 4
    assert {(c.sync_id, c.result, c.spindles) for c in cycles} == {(100, "NOK", 4)}
    document = json.loads(format_json(found))
    assert [d["spindle"] for d in document] == [1, 2, 3, 4]
    assert {d["cycle"]["result"] for d in document} == {"NOK"}
    assert document[0]["cycle"]["nok_reasons"] == "spindle 3 NOK"
    table = format_table(found).splitlines()
    assert table[0].split()[5:8] == ["run", "spindle", "cycle"]
    assert table[1].split()[6:9] == ["1", "100", "NOK"]
    assert format_csv(found).splitlines()[0].endswith(",pulses,spindle,sync_id,cycle_result")


def test_a_spindle_with_no_result_has_no_row_and_the_others_say_the_cycle_is_nok(
    target: StoreTarget,
) -> None:
    cycle = cycle_of(200, {1: "OK", 2: None})
    with ResultsStore(target) as store:
        store.add(spindle_results(200, 1))
        assert store.add_cycles([cycle], 5) == 1
        (found,) = store.find(ResultsQuery(part_id="P7"))
    assert found.cycle is not None and found.cycle.result == "NOK"
    assert found.cycle.nok_reasons == "spindle 2 no result" and found.cycle.spindles == 2


def test_a_single_spindle_stations_table_has_no_spindle_columns(target: StoreTarget) -> None:
    with ResultsStore(target) as store:
        store.add([stored_result(factories.result(1), "A", None, None, 1)])
        found = store.find(ResultsQuery())
    assert "spindle" not in format_table(found).splitlines()[0]
    assert "spindle" not in json.loads(format_json(found))[0]
    assert "cycle" not in json.loads(format_json(found))[0]


def test_the_store_a_single_spindle_station_wrote_before_reads_as_it_did(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``tests/data/single-spindle``: the store of version 5 that ``boltwatch up`` wrote before
    spindles, migrated by a writer, answers ``results --json`` with what it answered then."""
    folder = tmp_path / "recordings"
    folder.mkdir()
    shutil.copy(SINGLE_SPINDLE / "results.sqlite", folder / "results.sqlite")
    with ResultsStore(StoreTarget(sqlite_path=folder / "results.sqlite")) as store:
        assert store.migrated_from == 5
    capsys.readouterr()
    assert main(["results", "--recordings", str(folder), "--json"]) == 0
    answered = capsys.readouterr().out
    assert json.loads(answered) == json.loads((SINGLE_SPINDLE / "results.json").read_text())


def test_a_cycle_file_rebuilds_its_spindles_results_with_their_cycle(tmp_path: Path) -> None:
    """``results rebuild`` (and the recorder's catch-up) reads a cycle's file: every
    spindle's result and the cycle's common result, stored together."""
    from shared.config import StationPlace
    from shared.contract import encode
    from shared.recordings import classify, file_path
    from shared.recordings.mcap import McapSink
    from shared.results.recordings_reading import fill_from_recordings

    folder = tmp_path / "recordings"
    path = file_path(folder, "st1", 300, factories.T0)
    path.parent.mkdir(parents=True)
    cycle = cycle_of(300, {1: "OK", 2: "OK", 3: "OK"})
    with McapSink(path, {}, 300, factories.T0) as sink:
        for stored in spindle_results(300, 3):
            sink.write(classify("boltwatch/st1/results", encode(stored.result), factories.T0))
        sink.write(classify("boltwatch/st1/cycles", encode(cycle), factories.T0))
    target = StoreTarget(sqlite_path=folder / "results.sqlite")
    with ResultsStore(target) as store:
        counts = fill_from_recordings(store, [path], {"st1": StationPlace()}, "box", lambda: 1)
        found = store.find(ResultsQuery(part_id="P7", oldest_first=True))
    assert counts.new == 3
    assert [(s.result.spindle, s.cycle.result if s.cycle else None) for s in found] == [
        (1, "OK"), (2, "OK"), (3, "OK"),
    ]  # fmt: skip
    assert {s.recording for s in found} == {str(path.resolve())}


def test_a_cycle_reads_back_by_its_sync_id_as_it_was_stored(target: StoreTarget) -> None:
    nok = cycle_of(20, {1: "OK", 2: "NOK", 3: None})
    ok = cycle_of(30, {1: "OK", 2: "OK"})
    with ResultsStore(target) as store:
        store.add(
            [
                stored_result(
                    factories.result(20 + k - 1, part_id="P7", spindle=k, sync_id=20, result=v),
                    "A",
                    None,
                    "box",
                    1,
                )
                for k, v in ((1, "OK"), (2, "NOK"))
            ]
        )
        store.add_cycles([nok, ok], 2)  # cycle 30's runs not stored (yet): OK, as it is
        assert store.cycle("st1", 20) == nok
        assert store.cycle("st1", 30) == ok
        assert store.cycle("st1", 40) is None
        assert store.cycle("st2", 20) is None
