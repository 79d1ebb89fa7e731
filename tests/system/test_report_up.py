"""``boltwatch report`` over the recordings of a real ``boltwatch up``.

The station tightens six joints (real processes, zenoh on loopback, CAN over
udp_multicast); the report's figures are checked against numpy computed from
the results read back from MCAP with the mcap library and json only.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from tests.support.router_process import boltwatch
from tests.support.station_files import write_station
from tests.support.station_up import read_recordings, run_up

pytestmark = pytest.mark.system

RUNS = 6


def test_report_over_runs_of_up(tmp_path: Path) -> None:
    station = write_station(tmp_path)
    run_up(station, runs=RUNS)
    out = tmp_path / "report"
    command = ["report", "--config", str(station)]
    report = boltwatch(*command, "--subgroup-size", "2", "--out", str(out), timeout_s=120)
    assert report.returncode == 0, report.stdout + report.stderr
    results = read_recordings(tmp_path / "recordings")["boltwatch/st1/results"]
    assert len(results) == RUNS
    assert f"{RUNS} results (from the results store " in report.stdout
    # the same figures from the recordings themselves
    scan = boltwatch(
        *command, "--from-recordings", "--subgroup-size", "2", "--out", str(tmp_path / "scan"),
        timeout_s=120,
    )  # fmt: skip
    assert scan.returncode == 0, scan.stdout + scan.stderr
    assert re.search(rf"^{RUNS} results \(from \d+ recordings\)$", scan.stdout, re.MULTILINE)
    assert report.stdout.splitlines()[1:-1] == scan.stdout.splitlines()[1:-1]
    # a part's tightenings found in the store, the runs whose results name it
    part = results[0]["part_id"]
    runs_of_part = sorted(r["run_id"] for r in results if r["part_id"] == part)
    assert part and len(runs_of_part) >= 2, results  # the rig's parts have several bolts
    found = boltwatch("results", "--config", str(station), "--part", part, "--json")
    assert found.returncode == 0, found.stdout + found.stderr
    rows = json.loads(found.stdout)
    assert sorted(row["run_id"] for row in rows) == runs_of_part
    assert all(Path(row["recording"]).is_file() for row in rows)
    preload = [result["final_force_n"]["value"] for result in results]
    low, high = results[-1]["final_force_n"]["min"], results[-1]["final_force_n"]["max"]
    mean, sigma = np.mean(preload), np.std(preload, ddof=1)
    cpk = min(high - mean, mean - low) / (3 * sigma)
    line = next(line for line in report.stdout.splitlines() if "final preload" in line)
    assert f"mean {mean:.6g} " in re.sub(r"\s+", " ", line), line
    assert f"Cp {(high - low) / (6 * sigma):.3g} Cpk {cpk:.2f}" in line, line
    noks = sum(1 for result in results if result["result"] == "NOK")
    assert f"{RUNS} runs, NOK {noks}" in report.stdout
    page = (out / "report.html").read_text()
    assert f"{cpk:.2f}" in page and "data:image/png;base64," in page
    assert (out / "report.png").read_bytes().startswith(b"\x89PNG")
