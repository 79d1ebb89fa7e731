"""A broken wear ledger is a fault, not a crash: reported, recorded around, moved aside.

``recordings/wear.sqlite`` replaced by random bytes, emptied (with the
recorder stopped, and under a running recorder), a SQLite file of another
schema, a ledger with corrupt pages: ``boltwatch wear`` says what in one
line (exit 2); the real recorder on a real zenoh session keeps recording
every run into MCAP, keeps the summaries waiting, says so in RecorderStats
and logs once; ``boltwatch wear reset`` (a separate process, as an operator
runs it) moves the file aside, keeping it, and the waiting runs go into the
new ledger. Runs still waiting when the recorder stops are counted by the
next one.
"""

from __future__ import annotations

import logging
import os
import sqlite3
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import zenoh

from services.cli.main import main
from shared.config import LoadedStation
from shared.contract import Sample, ToolState, channels
from shared.runtime import zenoh_config
from shared.wear import CONTRACT_LIMITS, WearLedger
from tests.support.factories import summary
from tests.support.listener import Listener
from tests.support.live_recorder import RunningRecorder, publish, wait_until
from tests.support.router_process import boltwatch

T0_NS = 1_700_000_000_000_000_000
SAMPLES = 50


def run_messages(run_id: int) -> list[tuple[str, Any]]:
    """A whole run of SAMPLES samples at 1 kHz with its summary, as the station publishes it."""
    t = T0_NS + run_id * 10_000_000_000
    end = t + SAMPLES * 1_000_000
    out: list[tuple[str, Any]] = [("tool", ToolState("st1", run_id, 7, 1, "running", t))]
    out += [
        ("samples", Sample("st1", run_id, n, t + n * 1_000_000, 50.0 + n, 0.1 * n, 1e4 + n))
        for n in range(SAMPLES)
    ]
    out.append(("tool", ToolState("st1", run_id, 7, 1, "done", end)))
    run = summary(
        run_id,
        events=4,
        stop_reason=None,
        process_intensity=0.5 * run_id,
        samples=SAMPLES,
        started_ns=t,
        ended_ns=end,
    )
    return [*out, ("runs", run)]


def healthy_ledger(path: Path, runs: int = 3) -> None:
    with WearLedger(path) as ledger:
        for run_id in range(1, runs + 1):
            summary = run_messages(run_id)[-1][1]
            ledger.add_run(summary, T0_NS, CONTRACT_LIMITS)


def random_bytes(path: Path) -> None:
    path.write_bytes(os.urandom(16384))


def empty(path: Path) -> None:
    path.write_bytes(b"")


def another_schema(path: Path) -> None:
    db = sqlite3.connect(path)
    db.execute("CREATE TABLE readings (sensor TEXT, value REAL)")
    db.commit()
    db.close()


def corrupt_pages(path: Path) -> None:
    """A ledger whose pages after the first (the runs table) are overwritten with noise."""
    healthy_ledger(path, runs=200)
    with path.open("r+b") as handle:
        handle.seek(4096)
        handle.write(os.urandom(path.stat().st_size - 4096))


BREAKS: dict[str, tuple[Callable[[Path], None], str]] = {
    "random bytes": (random_bytes, "not a SQLite file"),
    "empty": (empty, "it is empty (0 bytes)"),
    "another schema": (another_schema, "another schema: no table 'runs'"),
    "corrupt pages": (corrupt_pages, "malformed"),
}


@pytest.mark.parametrize("kind", list(BREAKS), ids=list(BREAKS))
def test_boltwatch_wear_says_what_is_wrong_in_one_line(
    kind: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    make, what = BREAKS[kind]
    path = tmp_path / "wear.sqlite"
    make(path)
    assert main(["wear", "--recordings", str(tmp_path)]) == 2
    captured = capsys.readouterr()
    (line,) = captured.err.splitlines()
    assert line.startswith(f"boltwatch wear: {path}: not a usable wear ledger: ")
    assert what in line
    assert line.endswith(f"; move it aside and start a new ledger: boltwatch wear reset "
                         f"--recordings {tmp_path}")  # fmt: skip
    assert captured.out == ""


def reset(recordings: Path) -> subprocess.CompletedProcess[str]:
    """``boltwatch wear reset`` in its own process, as an operator runs it."""
    return boltwatch("wear", "reset", "--recordings", str(recordings), timeout_s=60)


@pytest.mark.parametrize("kind", list(BREAKS), ids=list(BREAKS))
def test_reset_keeps_the_broken_file_and_starts_a_new_ledger(kind: str, tmp_path: Path) -> None:
    make, what = BREAKS[kind]
    path = tmp_path / "wear.sqlite"
    make(path)
    before = path.read_bytes()
    done = reset(tmp_path)
    assert done.returncode == 0, done.stderr
    assert "moved the broken wear ledger" in done.stdout and what in done.stdout
    (kept,) = tmp_path.glob("wear.sqlite.broken-*Z")
    assert kept.read_bytes() == before  # kept as it was: nothing deleted
    with WearLedger(path, read_only=True) as ledger:
        assert ledger.tools() == []
    refused = reset(tmp_path)  # the new one is healthy: nothing to do
    assert refused.returncode == 2
    assert refused.stderr.strip() == (
        f"boltwatch wear: {path}: a healthy wear ledger; nothing to reset"
    )


HOLD = """
import sqlite3, sys
db = sqlite3.connect(sys.argv[1])
db.execute("SELECT COUNT(*) FROM sqlite_master").fetchone()
print("open", flush=True)
sys.stdin.readline()
"""


def test_reset_refuses_a_ledger_a_process_has_open(tmp_path: Path) -> None:
    """A process holding a connection (the WAL's lock shows it) keeps its file in place."""
    path = tmp_path / "wear.sqlite"
    corrupt_pages(path)  # broken, yet SQLite still opens it: a writer may hold it
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLD, str(path)], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
        text=True,
    )  # fmt: skip
    assert holder.stdin is not None and holder.stdout is not None
    try:
        assert holder.stdout.readline().strip() == "open"
        done = reset(tmp_path)
    finally:
        holder.stdin.close()
        holder.wait(10)
        holder.stdout.close()
    assert done.returncode == 2
    assert f"open in process {holder.pid} (" in done.stderr
    assert "a ledger in use is not moved: stop that process first" in done.stderr
    assert list(tmp_path.glob("wear.sqlite.broken-*")) == []
    assert reset(tmp_path).returncode == 0  # closed: now it moves


WHEN = [
    "random bytes before start",
    "emptied before start",
    "emptied while running",
    "another schema before start",
    "corrupt pages before start",
]


@pytest.mark.parametrize("when", WHEN)
def test_the_recorder_records_on_and_counts_the_waiting_runs_once_reset(
    when: str, station: LoadedStation, tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.INFO)
    recordings = station.recordings_folder
    ledger_file = recordings / "wear.sqlite"
    recordings.mkdir(parents=True, exist_ok=True)
    breaks = {
        "random": random_bytes,
        "emptied": empty,
        "another": another_schema,
        "corrupt": corrupt_pages,
    }
    if when.endswith("before start"):
        breaks[when.split(maxsplit=1)[0]](ledger_file)
    recorder = RunningRecorder(station)
    session = zenoh.open(zenoh_config("peer", connect=station.config.zenoh.listen))
    try:
        heard = Listener(session, "st1", (channels.RECORDER.topic,))
        wear = recorder.service.wear
        assert wear is not None
        if when == "emptied while running":
            publish(session, run_messages(1))
            wait_until(lambda: wear.counted == 1, "run 1 counted")
            os.truncate(ledger_file, 0)
        for run_id in (2, 3):
            publish(session, run_messages(run_id))
        wait_until(lambda: wear.waiting == 2, "the summaries waiting")
        wait_until(
            lambda: any(s.waiting_summaries == 2 for s in heard.of("recorder")), "RecorderStats"
        )
        last = heard.of("recorder")[-1]
        assert last.recording and last.last_error is not None
        assert last.last_error.startswith(f"wear ledger: {ledger_file}: not a usable wear ledger")
        assert "boltwatch wear reset" in last.last_error
        broken_lines = [r for r in caplog.records if "wear ledger broken" in r.getMessage()]
        assert len(broken_lines) == 1 and broken_lines[0].levelno == logging.ERROR

        done = reset(recordings)
        assert done.returncode == 0, done.stderr
        wait_until(lambda: wear.waiting == 0, "the waiting runs in the new ledger")
        wait_until(
            lambda: any(s.last_error is None for s in heard.of("recorder")[-2:]), "RecorderStats"
        )
        publish(session, run_messages(4))
        wait_until(lambda: wear.counted == (4 if when == "emptied while running" else 3), "run 4")
        heard.close()
    finally:
        session.close()
        recorder.finish()
    with WearLedger(ledger_file, read_only=True) as ledger:
        (tool,) = ledger.tools()
    assert (tool.runs, tool.total_intensity) == (3, 0.5 * (2 + 3 + 4))
    runs_recorded = sorted(p.name.split("_")[1] for p in recordings.glob("st1/*/*.mcap"))
    expected = ["run1"] if when == "emptied while running" else []
    assert runs_recorded == [*expected, "run2", "run3", "run4"]  # MCAP never stopped
    assert len(list(recordings.glob("wear.sqlite.broken-*Z"))) == 1


def test_runs_waiting_when_the_recorder_stops_are_counted_by_the_next(
    station: LoadedStation,
) -> None:
    recordings = station.recordings_folder
    recordings.mkdir(parents=True, exist_ok=True)
    random_bytes(recordings / "wear.sqlite")
    recorder = RunningRecorder(station)
    session = zenoh.open(zenoh_config("peer", connect=station.config.zenoh.listen))
    try:
        for run_id in (1, 2):
            publish(session, run_messages(run_id))
        wear = recorder.service.wear
        assert wear is not None
        wait_until(lambda: wear.waiting == 2, "the summaries waiting")
    finally:
        session.close()
        recorder.finish()
    waiting_file = recordings / "wear.sqlite.waiting"
    assert len(waiting_file.read_text().splitlines()) == 2
    assert reset(recordings).returncode == 0

    again = RunningRecorder(station)
    try:
        next_wear = again.service.wear
        assert next_wear is not None
        wait_until(lambda: next_wear.counted == 2, "the kept runs counted")
        wait_until(lambda: not waiting_file.exists(), "the waiting file removed")
    finally:
        again.finish()
    with WearLedger(recordings / "wear.sqlite", read_only=True) as ledger:
        assert ledger.tool(7).runs == 2
