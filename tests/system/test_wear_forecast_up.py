"""``boltwatch wear`` and ``report`` after a real ``boltwatch up``: each tool's forecast.

The simulated station tightens six joints (real processes, zenoh on loopback, CAN over
udp_multicast) with a service threshold its tool passes within a few runs. ``boltwatch
wear --json`` must give the tool its forecast (runs left, and a date or the reason for
none: due now here; against a threshold far off, no date for a tool of minutes' history,
and why) and the share of its wear since its service per program, as the recorded run
summaries add up; ``boltwatch report`` its "Tool wear".
"""

from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path

import pytest

from tests.support.router_process import boltwatch
from tests.support.station_files import write_station
from tests.support.station_up import read_recordings, run_up

pytestmark = pytest.mark.system

RUNS = 6  # enough to pass the threshold twice over (`up --runs 20` says no more)
THRESHOLD = 2.0e6  # some 1e6 a run: due after a few runs


def test_wear_after_up_gives_the_tool_its_forecast_and_its_wear_per_program(
    tmp_path: Path,
) -> None:
    threshold = {"[recorder]\n": f"[recorder]\nwear_service_threshold = {THRESHOLD}\n"}
    station = write_station(tmp_path, replacements=threshold)
    run_up(station, runs=RUNS)
    wear = boltwatch("wear", "--config", str(station), "--json")
    assert wear.returncode == 0, wear.stdout + wear.stderr
    (tool,) = json.loads(wear.stdout)
    told = tool["forecast"]
    assert (tool["tool_id"], tool["runs"], told["threshold"]) == (7, RUNS, THRESHOLD)
    assert told["state"] == "due" and told["runs_left"] == 0
    assert told["reason"] == "past its service threshold: due now"
    # its wear per program, as the run summaries the station put add up
    summaries = read_recordings(tmp_path / "recordings")["boltwatch/st1/runs"]
    per_program: dict[str, float] = defaultdict(float)
    for summary in summaries:
        per_program[f"program {summary['program_id']}"] += summary["process_intensity"]
    total = sum(per_program.values())
    shares = {part["name"]: part["share"] for part in tool["wear_by"]["program"]}
    assert shares == pytest.approx({name: value / total for name, value in per_program.items()})
    assert sum(shares.values()) == pytest.approx(1.0)
    (joint,) = tool["wear_by"]["joint"]  # every program tightens the station's joint
    assert joint["share"] == pytest.approx(1.0) and joint["name"].startswith("M14")

    far = boltwatch("wear", "--config", str(station), "--json", "--threshold", "1e15")
    assert far.returncode == 0, far.stdout + far.stderr
    (tool,) = json.loads(far.stdout)
    told = tool["forecast"]
    assert (told["state"], told["due_ns"]) == ("none", None)
    assert "a forecast needs 7 days of history" in told["reason"]
    assert told["runs_left"] > 0  # at its intensity per run so far

    out = tmp_path / "report"
    report = boltwatch("report", "--config", str(station), "--out", str(out), timeout_s=120)
    assert report.returncode == 0, report.stdout + report.stderr
    assert "tool wear (from " in report.stdout
    assert "  tool 7: due now (past its service threshold); runs left 0" in report.stdout
    page = (out / "report.html").read_text()
    assert "<h2>Tool wear</h2>" in page and "<h3>Tool 7</h3>" in page
