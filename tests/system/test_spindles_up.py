"""``boltwatch up --spindles 4``: a multi-spindle station end to end (real processes, zenoh on
loopback, CAN over udp_multicast).

What the multi-spindle issue asks: ``--runs 5`` records 5 cycles of 4 spindles; ``results
--json`` lists 20 tightenings, each with its spindle and the sync id its cycle's other three
share, and the cycle's common result; ``results --part`` finds a part's cycle whole; every
sample of every spindle is recorded, one file per cycle.
"""

from __future__ import annotations

import json
from collections import Counter, defaultdict
from pathlib import Path

import pytest

from tests.support.router_process import boltwatch
from tests.support.station_files import write_station
from tests.support.station_up import read_recordings, run_up

pytestmark = pytest.mark.system

CYCLES = 5
SPINDLES = 4


def test_up_with_four_spindles_records_each_cycle_whole(tmp_path: Path) -> None:
    station = write_station(tmp_path)
    result = run_up(station, CYCLES, "--spindles", str(SPINDLES), "--program", "2")
    assert f"{CYCLES} cycles, " in result.stdout and "spindle" in result.stdout

    found = boltwatch("results", "--config", str(station), "--json", timeout_s=60, check=True)
    tightenings = json.loads(found.stdout)
    assert len(tightenings) == CYCLES * SPINDLES
    by_sync: dict[int, list[dict]] = defaultdict(list)
    for tightening in tightenings:
        by_sync[tightening["sync_id"]].append(tightening)
    assert len(by_sync) == CYCLES
    for sync_id, cycle in by_sync.items():
        assert sorted(t["spindle"] for t in cycle) == [1, 2, 3, 4], sync_id
        assert len({t["part_id"] for t in cycle}) == 1  # one part a cycle
        assert len({t["tool_id"] for t in cycle}) == SPINDLES  # each spindle its own tool
        verdicts = {t["result"] for t in cycle}
        common = {t["cycle"]["result"] for t in cycle}
        assert common == {"OK" if verdicts == {"OK"} else "NOK"}, cycle
        assert {t["cycle"]["sync_id"] for t in cycle} == {sync_id}

    part = tightenings[0]["part_id"]
    by_part = boltwatch(
        "results", "--config", str(station), "--part", part, "--json", timeout_s=60, check=True
    )
    whole = json.loads(by_part.stdout)
    assert sorted(t["spindle"] for t in whole) == [1, 2, 3, 4]
    assert len({t["recording"] for t in whole}) == 1  # the cycle's one file

    messages = read_recordings(tmp_path / "recordings")
    summaries = messages["boltwatch/st1/runs"]
    assert len(summaries) == CYCLES * SPINDLES
    samples = Counter(s["run_id"] for s in messages["boltwatch/st1/samples"])
    for summary in summaries:  # every spindle's every sample, between the bus and the file
        assert samples[summary["run_id"]] == summary["samples"], summary["run_id"]
    bus = messages["boltwatch/st1/bus"][-1]
    assert bus["missed_samples"] == 0 and bus["counter_gaps"] == 0
    assert len(messages["boltwatch/st1/cycles"]) == CYCLES
