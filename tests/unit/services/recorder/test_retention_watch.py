"""The line's recorder applies ``[retention]`` itself: at its start and every few minutes, on a
thread of its own, it deletes the recordings the policy lets go, keeps those whose results
are not stored, never touches the file it records into, logs what it did and says it in its
RecorderStats."""

from __future__ import annotations

import logging
import time
from pathlib import Path

import pytest
import zenoh

from services.recorder.retention_watch import RetentionWatch
from shared.config import LoadedStation, load_station
from shared.contract import RecorderStats, decode, encode
from shared.recordings import unfinished_files
from shared.results import store_target
from shared.retention import retention_scopes
from shared.runtime import zenoh_config
from tests.support.live_recorder import (
    RunningRecorder,
    free_port,
    publish,
    wait_until,
    write_station_file,
)
from tests.support.postgres_server import PostgresServer
from tests.support.recorded_runs import recorded_files, run_messages
from tests.support.retention_files import DAY_NS, run_result, store, write_run_file

RETENTION = {"keep_days": 30, "keep_nok_days": 365}


def _station(
    tmp_path: Path, retention: dict[str, int] | None = RETENTION, database: str | None = None
) -> LoadedStation:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    path = write_station_file(
        tmp_path / "station.toml",
        tmp_path / "recordings",
        listen=[endpoint],
        recorder={} if database is None else {"results_database": database},
        retention=retention,
    )
    return load_station(path)


def test_the_recorder_deletes_what_the_policy_lets_go_and_keeps_what_is_not_stored(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    station = _station(tmp_path)
    folder = station.recordings_folder
    target = store_target(folder, None)
    now_ns = time.time_ns()

    def recorded(run_id: int, days_ago: float, verdict: str | None, stored: bool) -> Path:
        results = [] if verdict is None else [run_result(run_id, verdict)]
        path = write_run_file(folder, run_id, now_ns - round(days_ago * DAY_NS), results)
        if stored:
            store(target, results, path)
        return path

    ok = recorded(1, 40, "OK", stored=True)
    nok = recorded(2, 40, "NOK", stored=True)
    unstored = recorded(3, 40, "OK", stored=False)
    aborted = recorded(4, 40, None, stored=False)
    yesterday = recorded(5, 1, "OK", stored=True)
    caplog.set_level(logging.INFO, logger="services.recorder.retention_watch")
    recorder = RunningRecorder(station)
    try:
        watch = recorder.service.retention
        assert watch is not None
        wait_until(lambda: watch.passes >= 1, "the first retention pass")
        assert not ok.exists() and not aborted.exists()
        assert not ok.with_suffix(".rrd").exists() and not aborted.with_suffix(".rrd").exists()
        assert nok.exists() and unstored.exists() and yesterday.exists()
        session = zenoh.open(zenoh_config("peer", connect=station.config.zenoh.listen))
        try:
            publish(session, [*run_messages(10, 50), ("results", run_result(10))])
        finally:
            session.close()
        wait_until(lambda: bool(unfinished_files(folder)), "run 10's file (being written)")
        (stats,) = recorder.service.stats(time.time_ns())
        assert (stats.recordings_deleted, stats.recordings_kept_unstored) == (2, 1)
        assert decode(RecorderStats, encode(stats)) == stats
    finally:
        recorder.finish()
    assert len(recorded_files(station)) == 4  # nok, unstored, yesterday, run 10 (open)
    lines = [record.getMessage() for record in caplog.records]
    assert any("curves kept 30 days, NOK 365 days" in line for line in lines)
    deleted = [line for line in lines if line.startswith("retention: deleted 2 files")]
    assert len(deleted) == 1 and "2 older than keep_days (30 days)" in deleted[0]
    kept = [r for r in caplog.records if "past their time kept" in r.getMessage()]
    assert [r.levelno for r in kept] == [logging.WARNING]
    assert "1 file: results not in the store" in kept[0].getMessage()
    assert str(unstored) in kept[0].getMessage()


def test_without_a_rule_the_recorder_deletes_nothing_and_runs_no_pass(tmp_path: Path) -> None:
    station = _station(tmp_path, retention=None)
    old = write_run_file(station.recordings_folder, 1, time.time_ns() - 4000 * DAY_NS)
    recorder = RunningRecorder(station)
    try:
        assert recorder.service.retention is None
        (stats,) = recorder.service.stats(time.time_ns())
        assert (stats.recordings_deleted, stats.recordings_kept_unstored) == (0, 0)
    finally:
        recorder.finish()
    assert old.exists()


def test_a_file_the_recorder_has_open_is_never_deleted(tmp_path: Path) -> None:
    """The watch alone, a pass every 0.1 s: an old stored file stays while the worker says it
    is open, and goes at the first pass after it says it is not."""
    station = _station(tmp_path)
    folder = station.recordings_folder
    target = store_target(folder, None)
    now_ns = time.time_ns()
    old = write_run_file(folder, 1, now_ns - 40 * DAY_NS, [run_result(1)])
    newest = write_run_file(folder, 2, now_ns - 2 * DAY_NS, [run_result(2)])
    store(target, [run_result(1), run_result(2)], old)
    (scope,) = retention_scopes([station])
    watch = RetentionWatch(scope, interval_s=0.1)
    try:
        assert watch.passes == 0  # no pass before the worker says which files are open
        watch.open_files([old])
        wait_until(lambda: watch.passes >= 3, "three passes")
        assert old.exists() and newest.exists()
        watch.open_files([])
        wait_until(lambda: watch.deleted["st1"] == 1, "the old file deleted once closed")
        assert not old.exists() and newest.exists()
    finally:
        watch.close()


def test_nothing_is_deleted_while_the_store_cannot_be_asked(
    tmp_path: Path, caplog: pytest.LogCaptureFixture, own_postgres_server: PostgresServer
) -> None:
    """A plant's PostgreSQL stopped: passes fail, delete nothing, say it once; back: the old
    stored file goes at the next pass."""
    server = own_postgres_server
    station = _station(tmp_path, database=server.url)
    folder = station.recordings_folder
    target = store_target(folder, server.url)
    now_ns = time.time_ns()
    old = write_run_file(folder, 1, now_ns - 40 * DAY_NS, [run_result(1)])
    write_run_file(folder, 2, now_ns - 2 * DAY_NS, [run_result(2)])
    store(target, [run_result(1), run_result(2)], old)
    server.stop()
    (scope,) = retention_scopes([station])
    caplog.set_level(logging.INFO, logger="services.recorder.retention_watch")
    watch = RetentionWatch(scope, interval_s=0.1)
    try:
        watch.open_files([])
        wait_until(lambda: watch.last_error is not None, "a failed pass")
        time.sleep(0.5)  # a few more attempts
        assert old.exists() and watch.passes == 0
        server.start()
        wait_until(lambda: watch.deleted["st1"] == 1, "the old file deleted")
        assert not old.exists() and watch.last_error is None
    finally:
        watch.close()
    failing = [r for r in caplog.records if "nothing is deleted until" in r.getMessage()]
    assert [r.levelno for r in failing] == [logging.WARNING]
    assert any("answers again" in r.getMessage() for r in caplog.records)


def test_a_symlink_loop_in_the_recordings_is_named_once_and_never_touched(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """A day folder and a run file that are links to themselves, beside an old stored file:
    the passes delete the old file, log each loop once (not every pass) and leave them."""
    station = _station(tmp_path)
    folder = station.recordings_folder
    now_ns = time.time_ns()
    old = write_run_file(folder, 1, now_ns - 40 * DAY_NS, [run_result(1)])
    newest = write_run_file(folder, 2, now_ns - 2 * DAY_NS, [run_result(2)])
    store(store_target(folder, None), [run_result(1), run_result(2)], old)
    loops = [old.parent.with_name("2000-01-01"), old.with_name("st1_run9_000000.mcap")]
    for loop in loops:
        loop.symlink_to(loop.name)
    (scope,) = retention_scopes([station])
    caplog.set_level(logging.WARNING, logger="services.recorder.retention_watch")
    watch = RetentionWatch(scope, interval_s=0.1)
    try:
        watch.open_files([])
        wait_until(lambda: watch.deleted["st1"] == 1 and watch.passes >= 3, "three passes")
    finally:
        watch.close()
    assert not old.exists() and newest.exists() and all(loop.is_symlink() for loop in loops)
    named = [r.getMessage() for r in caplog.records if "is a symlink loop" in r.getMessage()]
    assert sorted(named) == sorted(
        f"retention: {loop}: is a symlink loop; skipped, never touched" for loop in loops
    )
