"""``boltwatch import`` killed with SIGKILL at several moments, then run again: nothing half-done.

A real child process imports twelve real runs (with their ``.rrd``) and is
killed part way, five times in a row (at start-up, then each time right
after another run got its name), each restart going on from what the last
left. Whatever moment a kill lands on, every ``.mcap`` under its real
name is complete with all its samples, its predictor summary and its
``.rrd``; the wear ledger never holds a run twice. A last, unkilled import
finishes every run, skips none it has not finished, and leaves no temporary
file behind.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import pytest

from shared.offline.controller_import import read_copy
from shared.wear import WearLedger
from tests.support.paths import PROJECT_REAL_RUNS, REPO

pytestmark = pytest.mark.system

#: (runs finished, writing): kill once that many runs have their real names and, when
#: ``writing``, the next run's temporary file exists too (mid-write); None: at start-up.
KILL_POINTS = ((None, False), (1, True), (3, False), (6, True), (9, True))


def twelve_runs(folder: Path) -> dict[int, tuple[Path, int]]:
    """run id -> (a copy of a shipped run under that id, its samples)."""
    runs: dict[int, tuple[Path, int]] = {}
    for copy in range(3):
        for source in sorted(PROJECT_REAL_RUNS.glob("Ch_*.json")):
            document = json.loads(source.read_text())
            run_id = document["cycle"] * 10 + copy
            document["cycle"] = run_id
            path = folder / f"{source.stem}_{copy}.json"
            path.write_text(json.dumps(document))
            samples = sum(len(s["graph"]["time values"]) for s in document["tightening steps"])
            runs[run_id] = (path, samples)
    return runs


def start_import(paths: list[Path], recordings: Path) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [
            sys.executable,
            "-m",
            "services.cli",
            "import",
            *map(str, paths),
            "--recordings",
            str(recordings),
        ],
        cwd=REPO,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def wait_for(recordings: Path, finished: int, writing: bool, child: subprocess.Popen[str]) -> None:
    """Until ``finished`` runs have their real names and (``writing``) a temporary file is
    there too, or the child has ended."""
    deadline = time.monotonic() + 120.0
    while child.poll() is None and time.monotonic() < deadline:
        done = len(list(recordings.glob("cs351/*/[!.]*.mcap"))) >= finished
        if done and (not writing or list(recordings.glob("cs351/*/.*.importing.mcap"))):
            return
        time.sleep(0.001)


def check_what_is_there(recordings: Path, runs: dict[int, tuple[Path, int]]) -> int:
    """Every visible .mcap is a finished import; the ledger counts each run at most once."""
    finished = 0
    for path in recordings.glob("cs351/*/[!.]*.mcap"):  # not the hidden temporaries
        run_id = int(path.name.split("_run")[1].split("_")[0])
        copy = read_copy(path)
        assert copy.holds(runs[run_id][1]), copy
        assert path.with_suffix(".rrd").stat().st_size > 0
        finished += 1
    ledger_file = recordings / "wear.sqlite"
    if ledger_file.exists():
        with WearLedger(ledger_file, read_only=True) as ledger:
            counted = sum(tool.runs for tool in ledger.tools())
        assert finished <= counted <= len(runs)  # counted before its files get their names
    return finished


def test_an_import_killed_anywhere_leaves_whole_runs_and_the_next_one_finishes(
    tmp_path: Path,
) -> None:
    runs = twelve_runs(tmp_path)
    recordings = tmp_path / "recordings"
    paths = [path for path, _ in runs.values()]
    finished_after_kills = []
    for finished, writing in KILL_POINTS:
        child = start_import(paths, recordings)
        if finished is not None:
            wait_for(recordings, finished, writing, child)
        child.kill()
        child.communicate()
        finished_after_kills.append(check_what_is_there(recordings, runs))
    assert finished_after_kills[-1] < len(runs)  # the last kill did land mid-batch

    child = start_import(paths, recordings)
    out, err = child.communicate(timeout=120)
    assert child.returncode == 0, err
    last = out.splitlines()[-1]
    done = finished_after_kills[-1]
    assert last == (
        f"imported {len(runs) - done} of {len(runs)} runs into {recordings}, "
        f"{done} already there, 0 refused"
    ), (last, finished_after_kills)
    assert check_what_is_there(recordings, runs) == len(runs)
    assert [p for p in recordings.rglob(".*") if p.is_file()] == []  # no temporary left
    with WearLedger(recordings / "wear.sqlite", read_only=True) as ledger:
        assert sum(tool.runs for tool in ledger.tools()) == len(runs)
