"""The wear ledger under kill -9 and beside a reader, with real processes and real SQLite.

A child process feeds RunSummaries into the ledger through the recorder's own
:class:`WearWatch`, run after run, and says on stdout each run it has counted.
The test kills it with SIGKILL at random moments, many times; after each kill
the file passes ``PRAGMA integrity_check``, holds runs 1..K with no hole, its
totals are the sum of exactly those runs, and K is the last run the child
reported or the one after it (the one being written). Each restart redelivers
the last counted run first, which must not be counted twice.

The reader tests hold a real read transaction in another process (or a write
transaction, the other way round) and check that the other side never waits.
"""

from __future__ import annotations

import random
import sqlite3
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from shared.contract import RunSummary
from shared.wear import CONTRACT_LIMITS, WearLedger
from tests.support import factories
from tests.support.paths import REPO
from tests.support.router_process import boltwatch

pytestmark = pytest.mark.system

KILLS = 12
TOOL = 7
T0_NS = 1_700_000_000_000_000_000
S_NS = 1_000_000_000

#: Intensity of run n: exact binary fractions, so sums compare exactly.
WRITER = textwrap.dedent(
    """
    import sys
    from shared.wear.wear_bound import CONTRACT_LIMITS
    from services.recorder.wear_watch import WearWatch
    from tests.support.factories import summary as run

    path, first = sys.argv[1], int(sys.argv[2])
    watch = WearWatch(path, None, lambda alert: None, lambda summary: CONTRACT_LIMITS)
    run_id = first
    while True:
        summary = run(
            run_id, station="st1" if run_id % 2 else "st2", events=3, stop_reason=None,
            process_intensity=run_id * 0.25, samples=1000, started_ns=run_id * 10**10,
            ended_ns=run_id * 10**10 + 2 * 10**9,
        )
        counted = watch.on_summary(summary, run_id)
        print(f"{'counted' if counted else 'repeated'} {run_id}", flush=True)
        run_id += 1
    """
)


def intensity(run_id: int) -> float:
    return run_id * 0.25


def start_writer(path: Path, first: int) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [sys.executable, "-c", WRITER, str(path), str(first)],
        cwd=REPO,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def ledger_state(path: Path) -> tuple[str, list[int], float]:
    """(integrity_check, run ids, total intensity of tool 7) through a fresh connection."""
    db = sqlite3.connect(path)
    try:
        (check,) = db.execute("PRAGMA integrity_check").fetchone()
        runs = [r for (r,) in db.execute("SELECT run_id FROM runs ORDER BY run_id")]
    finally:
        db.close()
    with WearLedger(path, read_only=True) as ledger:
        total = ledger.tool(TOOL).total_intensity
    return str(check), runs, total


def test_kill_9_loses_at_most_the_run_being_written_and_never_counts_twice(
    tmp_path: Path,
) -> None:
    path = tmp_path / "wear.sqlite"
    chance = random.Random(69)
    committed = 0
    for kill in range(KILLS):
        writer = start_writer(path, max(committed, 1))
        assert writer.stdout is not None
        lines: list[str] = []
        # Let it count a random number of runs (waiting on its output, not on the clock),
        # then kill it at a random moment within the next run or so.
        wanted = chance.randint(1, 25)
        while len([line for line in lines if line.startswith("counted")]) < wanted:
            line = writer.stdout.readline()
            assert line, f"writer died: {writer.stderr.read() if writer.stderr else ''}"
            lines.append(line.strip())
        time.sleep(chance.uniform(0, 0.004))
        writer.kill()
        writer.wait(10)
        rest = writer.stdout.read()  # what it printed before the kill landed
        lines.extend(line.strip() for line in rest.splitlines() if line.strip())
        writer.stdout.close()
        if writer.stderr is not None:
            writer.stderr.close()

        if committed:  # the redelivered run came first and was not counted again
            assert lines[0] == f"repeated {committed}", (kill, lines[:2])
        reported = max(int(line.split()[1]) for line in lines if line.startswith("counted"))
        check, runs, total = ledger_state(path)
        assert check == "ok", (kill, check)
        assert runs == list(range(1, len(runs) + 1)), f"kill {kill}: a hole or a double"
        assert reported <= runs[-1] <= reported + 1, (kill, reported, runs[-1])
        assert total == sum(intensity(run) for run in runs)
        committed = runs[-1]
    assert committed > KILLS


def summary(run_id: int, station: str = "st1") -> RunSummary:
    """A 2 s run of tool 7 from T0 + ``run_id`` s."""
    return factories.summary(
        run_id,
        station=station,
        tool_id=TOOL,
        events=3,
        stop_reason=None,
        process_intensity=intensity(run_id),
        samples=1000,
        started_ns=T0_NS + run_id * S_NS,
        ended_ns=T0_NS + run_id * S_NS + 2 * S_NS,
    )


HOLD_READ = textwrap.dedent(
    """
    import sqlite3, sys
    db = sqlite3.connect(f"{sys.argv[1]}?mode=ro", uri=True, isolation_level=None)
    db.execute("BEGIN")
    (runs,) = db.execute("SELECT COUNT(*) FROM runs").fetchone()
    print(runs, flush=True)
    sys.stdin.readline()  # hold the read transaction until told
    (again,) = db.execute("SELECT COUNT(*) FROM runs").fetchone()
    db.execute("COMMIT")
    (after,) = db.execute("SELECT COUNT(*) FROM runs").fetchone()
    print(again, after, flush=True)
    """
)


def test_a_reader_holding_a_read_transaction_never_blocks_the_writer(tmp_path: Path) -> None:
    path = tmp_path / "wear.sqlite"
    with WearLedger(path) as ledger:
        ledger.add_run(summary(1), T0_NS, CONTRACT_LIMITS)
    reader = subprocess.Popen(
        [sys.executable, "-c", HOLD_READ, path.resolve().as_uri()],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    assert reader.stdin is not None and reader.stdout is not None
    try:
        assert reader.stdout.readline().strip() == "1"  # its snapshot is open
        # busy timeout 0: any lock wait would raise "database is locked" at once
        with WearLedger(path, busy_timeout_s=0.0) as writer:
            for run_id in range(2, 52):
                assert writer.add_run(summary(run_id), T0_NS, CONTRACT_LIMITS)
            assert writer.tool(TOOL).runs == 51
        reader.stdin.write("go\n")
        reader.stdin.flush()
        # inside its transaction it still sees its snapshot; after it, everything
        assert reader.stdout.readline().split() == ["1", "51"]
    finally:
        reader.stdin.close()
        reader.wait(10)
        reader.stdout.close()
    assert reader.returncode == 0


HOLD_WRITE = textwrap.dedent(
    """
    import sqlite3, sys
    db = sqlite3.connect(sys.argv[1], isolation_level=None)
    db.execute("BEGIN IMMEDIATE")
    db.execute("DELETE FROM runs")
    print("holding", flush=True)
    sys.stdin.readline()
    db.execute("ROLLBACK")
    """
)


def test_boltwatch_wear_reads_while_a_writer_holds_its_transaction(tmp_path: Path) -> None:
    path = tmp_path / "wear.sqlite"
    with WearLedger(path) as ledger:
        for run_id in (1, 2):
            ledger.add_run(summary(run_id, station=f"st{run_id}"), T0_NS, CONTRACT_LIMITS)
    writer = subprocess.Popen(
        [sys.executable, "-c", HOLD_WRITE, str(path)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    assert writer.stdin is not None and writer.stdout is not None
    try:
        assert writer.stdout.readline().strip() == "holding"
        result = boltwatch("wear", "--recordings", str(tmp_path), "--station", "st2", "--json")
    finally:
        writer.stdin.write("done\n")
        writer.stdin.close()
        writer.wait(10)
        writer.stdout.close()
    assert result.returncode == 0, result.stderr
    import json

    (line,) = json.loads(result.stdout)  # tool 7 ran at st2: all its runs count
    assert (line["tool_id"], line["runs"]) == (TOOL, 2)
    assert line["total_intensity"] == intensity(1) + intensity(2)
    assert line["stations"] == ["st1", "st2"]
