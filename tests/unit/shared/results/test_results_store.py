"""The results store: idempotent by (station, run), every criterion of a question, the
steps of a controller's result, what a reader is told where no store is."""

from __future__ import annotations

import dataclasses

import pytest

from shared.contract import JudgedFigure, ResultStep, TighteningResult
from shared.errors import StoreError
from shared.results import ResultsQuery, ResultsStore, StoreTarget, stored_result
from tests.support import factories

T0_NS = factories.T0
MINUTE_NS = 60_000_000_000


def _result(run_id: int, **changes: object) -> TighteningResult:
    return factories.result(run_id, time_ns=T0_NS + run_id * MINUTE_NS, **changes)


def _store(
    store: ResultsStore, *results: TighteningResult, line: str = "A", plant: str = "North"
) -> int:
    return store.add(
        [
            stored_result(
                r,
                line,
                f"/rec/{r.station}_run{r.run_id}.mcap",
                "box",
                1,
                plant=plant,
                station_name=f"{r.station} of line {line}",
            )
            for r in results
        ]
    )


def test_a_result_stored_twice_is_one_row_and_the_first_stays(target: StoreTarget) -> None:
    with ResultsStore(target) as store:
        first = _result(1, part_id="VIN1")
        assert _store(store, first, _result(2)) == 2
        assert _store(store, dataclasses.replace(first, part_id="other"), _result(3)) == 1
        found = store.find(ResultsQuery(oldest_first=True))
    assert [stored.result for stored in found] == [first, _result(2), _result(3)]
    assert found[0].recording == "/rec/st1_run1.mcap" and found[0].recording_host == "box"
    assert (found[0].plant, found[0].line, found[0].station_name) == ("North", "A", "st1 of line A")


def test_a_controller_result_comes_back_whole_with_its_steps(target: StoreTarget) -> None:
    steps = [
        ResultStep("Rundown", "TF Angle", 720.0, 731.5, "OK"),
        ResultStep("Tightening 1.4", "TF Torque", 25.0, None, "NOK"),
        ResultStep("Relax", "", None, None, "not_judged"),
    ]
    result = _result(
        4,
        source="controller",
        part_id="WVWZZZ1JZXW000001",
        batch_counter=3,
        result="NOK",
        nok_reasons="torque low",
        final_torque_nm=JudgedFigure(23.1, 24.0, 27.0, "low"),
        final_angle_deg=JudgedFigure(731.5, None, None, "not_judged"),
        final_force_n=JudgedFigure(None, None, None, "not_judged"),
        stop_reason=None,
        events=None,
        process_intensity=None,
        steps=steps,
    )
    with ResultsStore(target) as store:
        _store(store, result, _result(5))
        (found,) = store.find(ResultsQuery(part_id="WVWZZZ1JZXW000001"))
    assert found.result == result


def test_many_results_of_several_stations_come_back_each_with_its_own_steps(
    target: StoreTarget,
) -> None:
    # more runs of a station than one statement reads the steps of, the same run ids at
    # two stations, results with and without steps
    def result(station: str, run_id: int) -> TighteningResult:
        steps = [
            ResultStep(f"{station} run {run_id} step {index}", "TF Torque", 25.0, run_id, "OK")
            for index in range(run_id % 4)
        ]
        return _result(run_id, station=station, source="controller", steps=steps)

    made = [result(station, run_id) for run_id in range(1, 1202) for station in ("st1", "st2")]
    with ResultsStore(target) as store:
        _store(store, *made)
        found = store.find(ResultsQuery(limit=None, oldest_first=True))
    assert [stored.result for stored in found] == made


def test_each_criterion_finds_its_tightenings_newest_first(target: StoreTarget) -> None:
    with ResultsStore(target) as store:
        _store(store, _result(1, part_id="P1"), _result(2, part_id="P1", program_id=3))
        _store(store, _result(3, part_id="P2", station="st2", tool_id=9), line="B")
        _store(store, _result(4, result="NOK", nok_reasons="preload low", station="st2"), line="B")
        _store(store, _result(5, station="st9"), line="B", plant="South")

        def runs(**criteria: object) -> list[tuple[str, int]]:
            query = ResultsQuery(**criteria)  # type: ignore[arg-type]
            return [(s.result.station, s.result.run_id) for s in store.find(query)]

        assert runs(part_id="P1") == [("st1", 2), ("st1", 1)]
        assert runs(plant="South") == [("st9", 5)]
        assert runs(plant="North", line="B") == [("st2", 4), ("st2", 3)]
        assert runs(stations=["st2"]) == [("st2", 4), ("st2", 3)]
        assert runs(stations=["st1", "st2"], limit=3) == [("st2", 4), ("st2", 3), ("st1", 2)]
        assert runs(line="A") == [("st1", 2), ("st1", 1)]
        assert runs(program_id=3) == [("st1", 2)]
        assert runs(tool_id=9) == [("st2", 3)]
        assert runs(verdict="NOK") == [("st2", 4)]
        assert runs(verdict="OK", stations=["st2"]) == [("st2", 3)]
        assert store.keys(ResultsQuery(verdict="OK", line="B")) == [("st9", 5), ("st2", 3)]
        assert runs(plant="North", limit=1) == [("st2", 4)]
        assert runs(since_ns=T0_NS + 2 * MINUTE_NS, until_ns=T0_NS + 4 * MINUTE_NS) == [
            ("st2", 3),
            ("st1", 2),
        ]
        assert runs(part_id="P1", program_id=3) == [("st1", 2)]
        assert runs(part_id="nowhere") == []
        assert store.count(ResultsQuery(stations=["st1", "st2"], limit=1)) == 4
        assert store.count(ResultsQuery(plant="North")) == 4


def test_the_newest_stored_result_of_stations(target: StoreTarget) -> None:
    with ResultsStore(target) as store:
        assert store.last_stored_ns(["st1"]) is None
        store.add([stored_result(_result(1), "", None, None, 500)])
        store.add([stored_result(_result(2, station="st2"), "", None, None, 900)])
        assert store.last_stored_ns(["st1"]) == 500
        assert store.last_stored_ns(["st1", "st2"]) == 900


def test_a_recording_read_is_remembered_with_its_size_and_time(target: StoreTarget) -> None:
    with ResultsStore(target) as store:
        assert store.recording_read("box", "/rec/a.mcap") is None
        store.mark_read("box", "/rec/a.mcap", 100, 7, 2, 1)
        store.mark_read("box", "/rec/a.mcap", 150, 9, 3, 2)  # it grew, read again
        assert store.recording_read("box", "/rec/a.mcap") == (150, 9)
        assert store.recording_read("other-box", "/rec/a.mcap") is None


def test_a_reader_where_no_store_is_is_told_how_one_comes(target: StoreTarget) -> None:
    with pytest.raises(StoreError, match=r"no results store at .*results rebuild"):
        ResultsStore(target, create=False)
    if target.sqlite_path is not None:
        assert not target.sqlite_path.exists()


def test_a_part_id_is_stored_as_the_part_a_search_asks_for(target: StoreTarget) -> None:
    """A result's part id as another tool wrote it (a recording not ours, a bridge): spaces
    at either end (a scanner's padding) or none at all (""). The part search (the line's
    page, ``results --part``) asks for a part without them, as every writer of ours names
    one: stored so, the part is found; "" is no part (null)."""
    from services.dashboard.part_search import part_of

    with ResultsStore(target) as store:
        _store(store, _result(1, part_id=" VIN7  "), _result(2, part_id=""), _result(3))
        (found,) = store.find(ResultsQuery(part_id=part_of(" VIN7 ")))
        assert found.result.run_id == 1 and found.result.part_id == "VIN7"
        assert store.count(ResultsQuery(part_id="")) == 0
        assert [s.result.part_id for s in store.find(ResultsQuery(oldest_first=True))] == [
            "VIN7",
            None,
            None,
        ]
