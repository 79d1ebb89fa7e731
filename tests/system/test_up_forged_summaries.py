"""A forged RunSummary is not a tightening: ``boltwatch up`` and the wear ledger both say no.

The probe: a RunSummary with intensity 1e15 for a run that never ran,
put on ``boltwatch/st1/runs`` by a client of the line's router while ``up``
runs (plain tcp, the line's default), went into the wear ledger and
counted toward ``up --runs``. Now ``up`` counts a summary only for a run it
saw start on the station's tool channel, once; the recorder refuses the
intensity (beyond what the program's 320 Nm tool can take).
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest

from shared.contract import channels, encode
from tests.support.factories import summary
from tests.support.live_station import open_client
from tests.support.router_process import boltwatch
from tests.support.station_files import write_station
from tests.support.station_up import UP_TIMEOUT_S, read_recordings, start_up, wait_for_first_run

pytestmark = pytest.mark.system

RUNS = 3


def forged(run_id: int, intensity: float) -> bytes:
    """A summary of run ``run_id`` that just ended, as a predictor would put it."""
    now = time.time_ns()
    run = summary(
        run_id,
        events=40,
        process_intensity=intensity,
        samples=1700,
        started_ns=now - 1_700_000_000,
        ended_ns=now,
    )
    return encode(run)


def test_a_forged_summary_is_neither_a_run_of_up_nor_wear_in_the_ledger(tmp_path: Path) -> None:
    station = write_station(tmp_path)
    endpoint = next(
        line.split('"')[1] for line in station.read_text().splitlines() if "tcp/" in line
    )
    up = start_up(station, runs=RUNS)
    try:
        first = wait_for_first_run(up).splitlines()[-1]
        first_run_id = int(first.split()[0])
        session = open_client(endpoint)
        try:
            runs = session.declare_publisher(channels.RUNS.key("st1"))
            runs.put(forged(4242, 1e15))  # a run that never ran
            runs.put(forged(4243, 5e5))  # never ran either, however plausible
            runs.put(forged(first_run_id, 9e5))  # a run that ran, summarised again
            runs.undeclare()
        finally:
            session.close()
        output, _ = up.communicate(timeout=UP_TIMEOUT_S)
    finally:
        if up.poll() is None:
            up.kill()
    output = first + "\n" + output
    assert up.returncode == 0, output
    assert "run summaries not counted: st1: 2 of runs never started on its tool channel, " \
        "1 repeated" in output  # fmt: skip
    rows = [line.split()[0] for line in output.splitlines() if line[:1].isdigit() and "kN" in line]
    assert "4242" not in rows and "4243" not in rows  # in no table
    assert "run summary st1/run4242 not counted: no run 4242 started on st1's tool channel" \
        in output  # fmt: skip
    assert f"{RUNS} runs, |error| mean" in output

    recordings = tmp_path / "recordings"
    real = {s["run_id"] for s in read_recordings(recordings)["boltwatch/st1/samples"]}
    assert len(real) == RUNS and first_run_id in real
    wear = boltwatch("wear", "--recordings", str(recordings), "--json", timeout_s=60)
    assert wear.returncode == 0, wear.stderr
    (tool,) = json.loads(wear.stdout)
    # 1e15 was refused by the ledger; the plausible forgery for a run that never ran is a
    # figure the ledger cannot tell from a true one (the answer: TLS and access control)
    assert tool["runs"] == RUNS + 1
    assert tool["total_intensity"] < 1e10
    recorder_log = next((recordings / "logs").glob("up-*/recorder.log")).read_text()
    assert "run summary st1/run4242 (tool 7) not counted in the wear ledger" in recorder_log
