"""``boltwatch up --controller openprotocol``: the station without CAN, end to end.

Real processes as ``up`` runs them: router, recorder, the bridge (``serve
openprotocol``) and the rig as an Open Protocol controller over real TCP on
loopback. Every run gets its OK/NOK in the table, is recorded (MCAP with its
result and its curves as samples) and counted in the wear ledger under the
tool's serial from the controller's tool data.
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import pytest

from tests.support.live_recorder import free_port
from tests.support.router_process import boltwatch
from tests.support.station_files import write_station
from tests.support.station_up import read_recordings, run_up, wear_ledger_rows

pytestmark = pytest.mark.system

RUNS = 5


def test_up_with_an_open_protocol_controller_records_every_run(tmp_path: Path) -> None:
    station = write_station(tmp_path)
    station.write_text(
        station.read_text() + f'\n[openprotocol]\nhost = "127.0.0.1"\nport = {free_port()}\n'
    )
    result = run_up(station, RUNS, "--controller", "openprotocol")
    rows = [line.split() for line in result.stdout.splitlines()]
    # run, prog, target and unit, reached and unit, error %, result, ...
    verdicts = {
        int(row[0]): row[7]
        for row in rows
        if len(row) > 7 and row[0].isdigit() and row[1].isdigit()
    }
    assert sorted(verdicts) == list(range(1, RUNS + 1))  # the controller's ids from 1
    assert set(verdicts.values()) == {"OK"}, result.stdout
    assert f"{RUNS} results" in result.stdout and "Open Protocol 127.0.0.1:" in result.stdout

    messages = read_recordings(tmp_path / "recordings")
    summaries = messages["boltwatch/st1/runs"]
    assert sorted(s["run_id"] for s in summaries) == list(range(1, RUNS + 1))  # once each
    results = messages["boltwatch/st1/results"]
    assert len(results) == RUNS
    assert {r["source"] for r in results} == {"controller"}
    assert {r["tightening_id"] for r in results} == set(range(1, RUNS + 1))
    samples_by_run: dict[int, int] = defaultdict(int)
    for sample in messages["boltwatch/st1/samples"]:
        samples_by_run[sample["run_id"]] += 1
    for summary in summaries:  # the controller's curves, every sample of the run
        assert samples_by_run[summary["run_id"]] == summary["samples"] > 1000, summary
    assert messages["boltwatch/st1/tool_data"][-1]["tool_serial"] == "SIM-7"

    wear = boltwatch("wear", "--config", str(station), timeout_s=60, check=True)
    (line,) = wear_ledger_rows(wear.stdout, 7)
    assert line[1:3] == ["SIM-7", str(RUNS)], wear.stdout
