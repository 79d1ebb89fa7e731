"""The wear ledger overwritten with random bytes while ``boltwatch up`` runs: recording goes on.

The probe: ``recordings/wear.sqlite`` replaced by random bytes under a
running station made the recorder exit at the next run summary, and all
recording stopped. Now, with the real processes of ``up``: every run is
still recorded whole in MCAP and ``up`` exits 0 with all its runs;
``boltwatch wear`` says what is wrong in one line; ``boltwatch wear reset``
(refused while the recorder still has the old file open, at most a couple of
seconds) moves the broken file aside, and the runs the recorder kept waiting
go into the new ledger, with every run after them.
"""

from __future__ import annotations

import json
import os
import subprocess
import time
from collections import defaultdict
from pathlib import Path

import pytest

from tests.support.router_process import boltwatch
from tests.support.station_files import write_station
from tests.support.station_up import UP_TIMEOUT_S, read_recordings, start_up, wait_for_first_run

pytestmark = pytest.mark.system

RUNS = 5


def read_rows(up: subprocess.Popen[str], count: int) -> list[str]:
    """The next ``count`` table rows ``up`` prints."""
    assert up.stdout is not None
    rows: list[str] = []
    while len(rows) < count:
        line = up.stdout.readline()
        assert line, f"up ended early after {rows}"
        if line.strip()[:1].isdigit() and "kN" in line:
            rows.append(line)
    return rows


def test_a_ledger_overwritten_under_up_is_reported_and_replaced_and_no_run_is_lost(
    tmp_path: Path,
) -> None:
    recordings = tmp_path / "recordings"
    ledger = recordings / "wear.sqlite"
    up = start_up(write_station(tmp_path), runs=RUNS)
    try:
        output = wait_for_first_run(up)
        deadline = time.monotonic() + 30  # up prints a run as the recorder files it: a race
        while not ledger.exists():
            assert time.monotonic() < deadline, "no wear ledger 30 s after the first run"
            time.sleep(0.05)
        with ledger.open("r+b") as handle:  # the recorder has it open
            handle.write(os.urandom(64 * 1024))
        output += "".join(read_rows(up, 1))

        wear = boltwatch("wear", "--recordings", str(recordings), timeout_s=60)
        assert wear.returncode == 2
        (line,) = wear.stderr.splitlines()
        assert line.startswith(f"boltwatch wear: {ledger}: not a usable wear ledger: ")
        assert line.endswith(f"boltwatch wear reset --recordings {recordings}")

        deadline = time.monotonic() + 30
        while (
            reset := boltwatch("wear", "reset", "--recordings", str(recordings), timeout_s=60)
        ).returncode:
            # the recorder lets go of the old file within its 2 s check
            assert "open in process" in reset.stderr, reset.stderr
            assert time.monotonic() < deadline, reset.stderr
            time.sleep(0.5)
        assert "moved the broken wear ledger" in reset.stdout
        rest, _ = up.communicate(timeout=UP_TIMEOUT_S)
        output += rest
    finally:
        if up.poll() is None:
            up.kill()
    assert up.returncode == 0, output
    assert f"{RUNS} runs, |error| mean" in output

    messages = read_recordings(recordings)  # every run whole in MCAP
    summaries = messages["boltwatch/st1/runs"]
    assert len(summaries) == RUNS
    by_run: dict[int, list[int]] = defaultdict(list)
    for sample in messages["boltwatch/st1/samples"]:
        by_run[sample["run_id"]].append(sample["sequence"])
    for summary in summaries:
        assert sorted(by_run[summary["run_id"]]) == list(range(summary["samples"]))

    (kept,) = recordings.glob("wear.sqlite.broken-*Z")  # kept, not deleted
    assert kept.stat().st_size > 0
    counted = boltwatch("wear", "--recordings", str(recordings), "--json", timeout_s=60)
    assert counted.returncode == 0, counted.stderr
    (tool,) = json.loads(counted.stdout)
    # the first run may have gone into the old ledger before it was overwritten; every
    # run after that is in the new one (none refused: true runs are within the bound)
    assert tool["runs"] in (RUNS - 1, RUNS)
    expected = sum(s["process_intensity"] for s in summaries[RUNS - tool["runs"] :])
    assert tool["total_intensity"] == pytest.approx(expected)
    log = next((recordings / "logs").glob("up-*/recorder.log")).read_text()
    assert log.count("wear ledger broken, nothing is written into it") == 1
    assert "works again" in log
