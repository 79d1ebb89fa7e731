"""The recorder puts every result it files into the results store, naming the file the run
is in; while the store fails the results wait and go in when it works again; results a
stopped recorder had not stored come from the recordings at its next start; a store of an
older boltwatch is migrated at start."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
import zenoh

from shared.config import LoadedStation, StationPlace, load_station
from shared.contract import TighteningResult
from shared.recordings.mcap import RecordingScan
from shared.results import (
    ResultsQuery,
    ResultsStore,
    StoredResult,
    StoreTarget,
    station_store,
    stored_result,
)
from shared.results.recordings_reading import fill_from_recordings
from shared.runtime import zenoh_config
from tests.support import factories
from tests.support.live_recorder import (
    RunningRecorder,
    free_port,
    publish,
    wait_until,
    write_station_file,
)
from tests.support.old_results_store import version_1_store
from tests.support.postgres_server import (
    PostgresServer,
)
from tests.support.recorded_runs import T0_NS, run_messages

WAIT_S = 30.0  # a bound: the writer stores every 0.2 s, retries a failing store every 5 s


def _run_with_result(run_id: int, part_id: str) -> list[tuple[str, object]]:
    """A whole run, then its result (as the predictor publishes them)."""
    result = factories.result(run_id, part_id=part_id, time_ns=T0_NS + run_id * 10**10 + 10**6)
    return [*run_messages(run_id, 50), ("results", result)]


#: where the station of these tests is ([station] plant, line, name)
PLACE = StationPlace("North", "B", "Wheel nuts")


def _station(tmp_path: Path, database: str | None = None) -> LoadedStation:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    recorder = {} if database is None else {"results_database": database}
    path = write_station_file(
        tmp_path / "station.toml",
        tmp_path / "recordings",
        listen=[endpoint],
        recorder=recorder,
        station={"plant": PLACE.plant, "line": PLACE.line, "name": PLACE.name},
    )
    return load_station(path)


def _stored(station: LoadedStation) -> list[StoredResult]:
    target = station_store(station)
    try:
        with ResultsStore(target, create=False) as store:
            return store.find(ResultsQuery(oldest_first=True))
    except Exception:
        return []


def _record(station: LoadedStation, runs: list[int]) -> RunningRecorder:
    recorder = RunningRecorder(station)
    session = zenoh.open(zenoh_config("peer", connect=station.config.zenoh.listen))
    try:
        for run_id in runs:
            publish(session, _run_with_result(run_id, f"VIN{run_id:04d}"))
    finally:
        session.close()
    return recorder


def _results_in(path: Path) -> list[TighteningResult]:
    from shared.contract import decode

    return [
        decode(TighteningResult, message.data)
        for _, _, message in RecordingScan(path).messages("/results")
    ]


@pytest.fixture(params=["sqlite", "postgresql"])
def station(request: pytest.FixtureRequest, tmp_path: Path) -> LoadedStation:
    if request.param == "sqlite":
        return _station(tmp_path)
    return _station(tmp_path, request.getfixturevalue("postgres_url"))


def test_each_result_is_stored_with_the_recording_it_is_in(station: LoadedStation) -> None:
    recorder = _record(station, [1, 2, 3])
    try:
        wait_until(lambda: len(_stored(station)) == 3, "three results stored", WAIT_S)
    finally:
        recorder.finish()
    stored = _stored(station)
    assert [s.result.part_id for s in stored] == ["VIN0001", "VIN0002", "VIN0003"]
    for row in stored:
        assert row.recording is not None
        assert StationPlace(row.plant, row.line, row.station_name) == PLACE
        assert row.result in _results_in(Path(row.recording)), row.recording
        assert f"_run{row.result.run_id}_" in Path(row.recording).name
    if station.config.recorder.results_database is None:
        assert (station.recordings_folder / "results.sqlite").is_file()


def test_a_version_1_store_is_migrated_by_the_recorder_at_start_losing_no_row(
    tmp_path: Path,
) -> None:
    """A line's store of the boltwatch before the plant model: the recorder migrates it at
    start; the row it held is as it was (no plant, no name), the new run's has both."""
    station = _station(tmp_path)
    old = stored_result(factories.result(1, part_id="VIN0001"), "B", "/rec/old.mcap", "box", 1)
    version_1_store(station_store(station), [old])
    recorder = _record(station, [2])
    try:
        wait_until(lambda: len(_stored(station)) == 2, "the new result stored", WAIT_S)
    finally:
        recorder.finish()
    kept, new = _stored(station)
    assert kept == old and (kept.plant, kept.station_name) == ("", "")
    assert StationPlace(new.plant, new.line, new.station_name) == PLACE


def test_a_store_down_keeps_results_waiting_and_the_next_start_finds_the_rest(
    tmp_path: Path, own_postgres_server: PostgresServer
) -> None:
    """Down while runs 1-2 are recorded: they wait; it comes back: they go in. Down again
    for runs 3-4 and the recorder stops: they are not lost, the next start reads them from
    the recordings (the catch-up)."""
    server = own_postgres_server
    station = _station(tmp_path, server.url)
    server.stop()
    recorder = _record(station, [1, 2])
    watch = recorder.service.results
    assert watch is not None
    try:
        wait_until(lambda: watch.waiting == 2, "2 results waiting")
        (stats,) = recorder.service.stats(time.time_ns())
        assert stats.waiting_results == 2 and stats.last_error is not None
        assert stats.last_error.startswith(f"results store {server.url}")
        server.start()
        wait_until(lambda: len(_stored(station)) == 2, "the waiting results stored", WAIT_S)
        assert watch.last_error is None
        server.stop()
        session = zenoh.open(zenoh_config("peer", connect=station.config.zenoh.listen))
        try:
            for run_id in (3, 4):
                publish(session, _run_with_result(run_id, f"VIN{run_id:04d}"))
        finally:
            session.close()
        wait_until(lambda: watch.waiting == 2, "runs 3-4 waiting")
    finally:
        recorder.finish()
    server.start()
    again = RunningRecorder(station)
    try:
        wait_until(lambda: len(_stored(station)) == 4, "runs 3-4 from the recordings", WAIT_S)
    finally:
        again.finish()
    stored = _stored(station)
    assert [s.result.part_id for s in stored] == [f"VIN{n:04d}" for n in (1, 2, 3, 4)]
    for row in stored:
        assert row.recording is not None
        assert row.result in _results_in(Path(row.recording))


def test_a_refused_results_payload_costs_no_result_of_its_file(tmp_path: Path) -> None:
    """A payload on ``results`` the recorder refused is kept raw in the run's file; reading
    the file again (rebuild, the catch-up) stores the file's good results and marks it read."""
    station = _station(tmp_path)
    recorder = RunningRecorder(station)
    session = zenoh.open(zenoh_config("peer", connect=station.config.zenoh.listen))
    try:
        run = _run_with_result(1, "VIN0001")
        publish(session, [*run[:-1], ("results", b'{"station": "st1", "run_id": "no"}'), run[-1]])
        wait_until(lambda: len(_stored(station)) == 1, "the good result stored", WAIT_S)
    finally:
        session.close()
        recorder.finish()
    (path,) = (row.recording for row in _stored(station))
    assert path is not None
    target = StoreTarget(sqlite_path=tmp_path / "again" / "results.sqlite")
    with ResultsStore(target) as store:
        counts = fill_from_recordings(store, [Path(path)], {"st1": PLACE}, "box", time.time_ns)
        assert (counts.read, counts.results, counts.new, counts.damaged) == (1, 1, 1, [])
        (again,) = store.find(ResultsQuery(plant=PLACE.plant))
        assert (again.line, again.station_name) == (PLACE.line, PLACE.name)
        assert store.recording_read("box", path) is not None


def test_a_result_that_cannot_be_a_measurement_is_kept_aside_live_and_at_catch_up(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """Run 2's result says 1e308 Nm (a faulty controller): the recorder records it, and the
    store keeps it aside, named in the log and counted, as ``results rebuild`` and ``report``
    name it; runs 1 and 3 are results. The next start, its store gone, reads the recordings
    again (the catch-up) and keeps the same aside."""
    from shared.contract import JudgedFigure

    station = _station(tmp_path)
    absurd = factories.result(
        2,
        part_id="VIN0002",
        time_ns=T0_NS + 2 * 10**10 + 10**6,
        final_torque_nm=JudgedFigure(1e308, 180.0, 240.0, "high"),
        result="NOK",
    )
    line = "station st1 run 2 (tool 7): final torque 1e+308 Nm, expected within ±1e+06 Nm"
    recorder = RunningRecorder(station)
    watch = recorder.service.results
    assert watch is not None
    session = zenoh.open(zenoh_config("peer", connect=station.config.zenoh.listen))
    try:
        publish(session, _run_with_result(1, "VIN0001"))
        publish(session, [*run_messages(2, 50), ("results", absurd)])
        publish(session, _run_with_result(3, "VIN0003"))
        wait_until(lambda: len(_stored(station)) == 2 and watch.refused == 1, "stored", WAIT_S)
    finally:
        session.close()
        recorder.finish()
    assert [s.result.run_id for s in _stored(station)] == [1, 3]
    assert any(line in record.getMessage() for record in caplog.records)
    with ResultsStore(station_store(station), create=False) as store:
        assert store.refused(ResultsQuery()) == [line]
        assert ("st1", 2) in store.verdicts([("st1", 2)])  # its recording may be let go

    (station.recordings_folder / "results.sqlite").unlink()
    caplog.clear()
    again = RunningRecorder(station)
    catch_up = again.service.results
    assert catch_up is not None
    try:
        wait_until(
            lambda: len(_stored(station)) == 2 and catch_up.refused == 1, "caught up", WAIT_S
        )
    finally:
        again.finish()
    assert any(line in record.getMessage() for record in caplog.records)
    with ResultsStore(station_store(station), create=False) as store:
        assert store.refused(ResultsQuery()) == [line]
