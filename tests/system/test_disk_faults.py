"""The recordings folder fails for real: full, read-only, not a folder, a file size limit.

Recording is not on the stop path: the recorder logs the fault (ERROR with the file and
the errno text, INFO when writing works again), counts what it drops, never crashes, and
records again at the next run (or within a few seconds) once the disk is back. Every
message is accounted for: readable in a file, or counted as dropped. The first tests
drive a Recorder in this process (or a child under RLIMIT_FSIZE); the last runs the
whole station as real processes on a tmpfs that fills up mid-run.
"""

from __future__ import annotations

import json
import logging
import os
import resource
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

from services.recorder.live.recorder import RETRY_INTERVAL_NS
from shared.contract import RunSummary
from shared.recordings import run_files, unfinished_files
from shared.recordings.mcap import RecordingScan
from shared.wear import CONTRACT_LIMITS, WearLedger, ledger_path
from tests.support import factories
from tests.support.disk_faults import fill_up, read_only, tmpfs
from tests.support.live_station import check_next_run_normal, live_station, recorded_sequences
from tests.support.paths import REPO
from tests.support.recorder_driver import RecorderDriver, recorded_messages

pytestmark = pytest.mark.system

RECORDER_LOG = "services.recorder.live.recorder"
#: the free-space reserve scaled to a 16 MB disk (by default the largest run file, 256 MB)
SCALED_RESERVE = {
    "flush_interval_s = 1.0": "flush_interval_s = 1.0\nfree_space_reserve_bytes = 2000000"
}


def errors_logged(caplog: pytest.LogCaptureFixture, level: int) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.name == RECORDER_LOG and r.levelno == level]


@pytest.mark.parametrize("batch_samples", [1, 10], ids=["samples", "batches"])
def test_a_disk_that_fills_up_mid_run(
    tmp_path: Path, caplog: pytest.LogCaptureFixture, batch_samples: int
) -> None:
    caplog.set_level(logging.INFO, logger=RECORDER_LOG)
    with tmpfs(tmp_path / "recordings", 1 << 20) as recordings:
        driver = RecorderDriver(tmp_path, recordings, batch_samples)
        driver.start_run(1)
        driver.samples(1, 2500)
        assert driver.recorder.recording_ok
        filler = fill_up(recordings)
        driver.samples(1, 3000)  # flushes fail: the file is abandoned, messages dropped

        recorder = driver.recorder
        assert not recorder.recording_ok and recorder.write_errors >= 1
        assert recorder.last_write_error is not None
        assert "No space left on device (ENOSPC)" in recorder.last_write_error
        (started,) = errors_logged(caplog, logging.ERROR)
        assert "recording failed" in started and str(recordings) in started
        assert "ENOSPC" in started

        filler.unlink()  # space comes back; the next retry (a few seconds) records again
        driver.samples(1, RETRY_INTERVAL_NS // 1_000_000 + 2000)
        assert recorder.recording_ok
        assert any("recording works again" in m for m in errors_logged(caplog, logging.INFO))
        driver.end_run(1)
        driver.start_run(2)
        driver.samples(2, 1500)
        driver.end_run(2)
        recorder.close()

        assert recorder.dropped_messages > 0
        # Nothing lost silently: every message received is in a file or counted as dropped.
        assert recorded_messages(recordings) + recorder.dropped_messages == recorder.messages
        assert recorder.abandoned_files  # the fault's file, readable up to its last flush
        abandoned = RecordingScan(recorder.abandoned_files[0])
        assert sum(1 for _ in abandoned.messages("/samples")) >= 2000  # flushed before the fault


def leave_free(folder: Path, free_bytes: int) -> Path:
    """Fill ``folder``'s file system until about ``free_bytes`` are left; the filler."""
    found = os.statvfs(folder)
    filler = folder / "filler.bin"
    filler.write_bytes(b"\0" * max(0, found.f_bavail * found.f_frsize - free_bytes))
    return filler


def test_below_the_free_space_reserve_no_file_is_opened_and_none_is_cut(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """A 4 MB tmpfs, a 1 MB reserve: the run open when the free space falls below it is
    finished whole; the next run opens no file (dropped, counted, one ERROR, the reason in
    the recorder's state); once there is room the next run is recorded again."""
    caplog.set_level(logging.INFO, logger=RECORDER_LOG)
    with tmpfs(tmp_path / "recordings", 4 << 20) as recordings:
        driver = RecorderDriver(tmp_path, recordings, reserve_bytes=1 << 20)
        recorder = driver.recorder
        driver.start_run(1)
        driver.samples(1, 1000)
        filler = leave_free(recordings, 512 << 10)
        driver.samples(1, 1000)  # the open file goes on: the reserve is there for it
        driver.end_run(1)
        driver.start_run(2)  # below the reserve: no file for run 2
        driver.samples(2, 1000)
        driver.end_run(2)
        assert not recorder.recording_ok and recorder.last_write_error is not None
        assert "below the reserve of 1.0 MB" in recorder.last_write_error
        assert "free_space_reserve_bytes" in recorder.last_write_error
        (started,) = errors_logged(caplog, logging.ERROR)
        assert "recording failed" in started
        (run1,) = run_files(recordings, "st1", 1)  # finished whole, under its name
        scan = RecordingScan(run1)
        assert sum(1 for _ in scan.messages("/samples")) == 2000 and scan.complete
        assert run_files(recordings, "st1", 2) == [] and unfinished_files(recordings) == []
        assert recorder.dropped_messages == 1002  # run 2, counted

        filler.unlink()  # room again: the next run is recorded
        driver.start_run(3)
        driver.samples(3, 1000)
        driver.end_run(3)
        assert recorder.recording_ok
        recorder.close()
        assert len(run_files(recordings, "st1", 3)) == 1
        assert recorded_messages(recordings) + recorder.dropped_messages == recorder.messages


def test_a_read_only_folder_then_writable_again(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.INFO, logger=RECORDER_LOG)
    with tmpfs(tmp_path / "recordings", 1 << 20) as recordings:
        driver = RecorderDriver(tmp_path, recordings)
        with read_only(recordings):
            driver.start_run(1)
            driver.samples(1, 1000)
            driver.end_run(1)
            recorder = driver.recorder
            assert not recorder.recording_ok
            assert recorder.last_write_error is not None
            assert "Read-only file system (EROFS)" in recorder.last_write_error
            assert recorder.dropped_messages == recorder.messages == 1002
        driver.start_run(2)  # the next run retries at once
        driver.samples(2, 1500)
        driver.end_run(2)
        assert recorder.recording_ok
        recorder.close()
        assert recorded_messages(recordings) + recorder.dropped_messages == recorder.messages
        assert len(errors_logged(caplog, logging.ERROR)) >= 1


def test_batches_that_cannot_open_a_file_are_counted_dropped(tmp_path: Path) -> None:
    """Read-only past the retry interval: the batch that retries the open is lost with it."""
    with tmpfs(tmp_path / "recordings", 1 << 20) as recordings:
        driver = RecorderDriver(tmp_path, recordings, batch_samples=10)
        with read_only(recordings):
            driver.start_run(1)
            driver.samples(1, RETRY_INTERVAL_NS // 1_000_000 + 1000)
            recorder = driver.recorder
            assert recorder.write_errors >= 2  # the run's start, then a batch's retry
            assert recorder.dropped_messages == recorder.messages
        driver.start_run(2)
        driver.samples(2, 1500)
        recorder.close()
        assert recorder.recording_ok
        assert recorded_messages(recordings) + recorder.dropped_messages == recorder.messages


def test_the_station_folder_replaced_by_a_file(tmp_path: Path) -> None:
    recordings = tmp_path / "recordings"
    recordings.mkdir()
    blocker = recordings / "st1"
    blocker.write_text("not a folder")
    driver = RecorderDriver(tmp_path, recordings)
    driver.start_run(1)
    driver.samples(1, 200)
    recorder = driver.recorder
    assert not recorder.recording_ok and recorder.write_errors >= 1
    assert recorder.last_write_error is not None
    assert str(blocker) in recorder.last_write_error
    assert "Not a directory (ENOTDIR)" in recorder.last_write_error
    blocker.unlink()
    driver.start_run(2)
    driver.samples(2, 1500)
    assert recorder.recording_ok
    recorder.close()
    assert recorded_messages(recordings) + recorder.dropped_messages == recorder.messages


def _limit_file_size() -> None:
    limit = 100_000
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))


def test_a_file_size_limit_gives_efbig_and_the_next_run_is_recorded(tmp_path: Path) -> None:
    """RLIMIT_FSIZE in a child process: the first run's file hits it, the next one fits."""
    result = subprocess.run(
        [sys.executable, "-m", "tests.support.recorder_driver", str(tmp_path)],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=60,
        preexec_fn=_limit_file_size,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    state = json.loads(result.stdout.splitlines()[-1])
    assert "File too large (EFBIG)" in state["last_write_error"], state
    assert "recording failed" in result.stderr
    assert state["write_errors"] >= 1 and state["dropped_messages"] > 0
    assert state["recording_ok"], state
    run2 = [Path(p) for p in state["closed"] if "_run2_" in p]
    assert run2
    scan = RecordingScan(run2[0])
    assert sum(1 for _ in scan.messages("/samples")) == 1000 and scan.complete
    recordings = tmp_path / "recordings"
    assert recorded_messages(recordings) + state["dropped_messages"] == state["messages"]


def _summary(run_id: int) -> RunSummary:
    """A 2 s run of 12 events: the ledger counts it (within its tool's bound)."""
    return factories.summary(
        run_id,
        events=12,
        stop_reason=None,
        process_intensity=1e6,
        samples=1500,
        started_ns=0,
        ended_ns=2 * 10**9,
    )


def test_a_full_disk_does_not_corrupt_the_wear_ledger(tmp_path: Path) -> None:
    with tmpfs(tmp_path / "recordings", 1 << 20) as recordings:
        ledger_file = recordings / "wear.sqlite"
        with WearLedger(ledger_file) as ledger:
            assert ledger.add_run(_summary(1), 1, CONTRACT_LIMITS)
            filler = fill_up(recordings)
            big = [_summary(n) for n in range(2, 2000)]
            with pytest.raises(sqlite3.OperationalError):
                for summary in big:  # the WAL grows until the disk refuses it
                    ledger.add_run(summary, 2, CONTRACT_LIMITS)
            filler.unlink()
        with WearLedger(ledger_file) as ledger:
            assert ledger.add_run(_summary(9999), 3, CONTRACT_LIMITS)
            (tool,) = ledger.tools()
        check = sqlite3.connect(ledger_file).execute("PRAGMA integrity_check").fetchone()
        assert check == ("ok",)
        assert tool.runs >= 2


def ledger_runs(recordings: Path) -> set[int]:
    """The runs the wear ledger counts (none while it is not made)."""
    try:
        with sqlite3.connect(ledger_path(recordings)) as ledger:
            return {row[0] for row in ledger.execute("SELECT run_id FROM runs")}
    except sqlite3.Error:
        return set()


def runs_of_each_file(recordings: Path) -> dict[str, set[int]]:
    """The runs whose samples each MCAP file holds (files under their names)."""
    return {
        path.name: {json.loads(message.data)["run_id"] for _, _, message in scan}
        for path in sorted(recordings.rglob("*.mcap"))
        for scan in [RecordingScan(path).messages("/samples")]
    }


def test_the_station_goes_on_while_the_recordings_disk_is_full(tmp_path: Path) -> None:
    """Real processes, an edge station as `boltwatch up` runs it: the whole recordings
    folder (run files, wear ledger, results store, the station's spool) is a 16 MB tmpfs with
    a reserve scaled to it, filled after the third run and freed three runs later. Runs go on
    and are decided meanwhile; the run in progress when room comes back is recorded from
    there on (or whole, what the spool or the recorder's memory still had) and every run is
    counted in the wear ledger, those made while nothing could be written too; no file holds
    another run's samples."""
    with (
        tmpfs(tmp_path / "recordings", 16 << 20) as recordings,
        live_station(tmp_path, placement="edge", replacements=SCALED_RESERVE) as station,
    ):
        station.wait_runs_summarised(3)
        filler = fill_up(recordings)
        station.wait_for(
            lambda: "No space left on device (ENOSPC)" in station.log("recorder"),
            "the recorder to log the full disk",
        )
        during = len(station.summaries())
        summaries = station.wait_runs_summarised(during + 3)  # tightening goes on
        assert all(station.decided(s.run_id) for s in summaries[during:])
        station.wait_for(lambda: station.running_run() is not None, "a run in progress")
        in_progress = station.running_run()
        filler.unlink()  # room again, mid-run
        station.wait_for(
            lambda: "recording works again" in station.log("recorder"), "the recorder to recover"
        )
        after = check_next_run_normal(station)
        assert in_progress is not None and in_progress < after
        summary = next(s for s in station.summaries() if s.run_id == in_progress)

        def recorded_from_room_on() -> bool:  # from some sample to its last, each once
            recorded = recorded_sequences(station.recordings, in_progress)
            return bool(recorded) and recorded == list(range(recorded[0], summary.samples))

        station.wait_for(
            recorded_from_room_on,
            f"run {in_progress}, in progress when room came back, recorded from there on",
            details=lambda: str(recorded_sequences(station.recordings, in_progress)[:3]),
        )
        summarised = {s.run_id for s in station.summaries() if s.run_id <= after}
        station.wait_for(
            lambda: summarised <= ledger_runs(recordings),
            "every run in the wear ledger",
            details=lambda: f"{sorted(summarised - ledger_runs(recordings))} not counted",
        )
        assert station.process("recorder").exit_code() is None
        assert "recording failed" in station.log("recorder")
    mixed = {name: runs for name, runs in runs_of_each_file(recordings).items() if len(runs) > 1}
    assert not mixed, mixed
