"""``boltwatch inspect --overlay`` over real runs: ``boltwatch up`` tightens three joints
with tight preload windows, then the overlay draws them found by their run ids."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from shared.offline.overlay import (
    align_index,
    build_overlay,
    find_run_files,
    parse_alignment,
    read_overlay_run,
)
from tests.support.paths import REPO
from tests.support.station_files import write_station
from tests.support.station_up import read_recordings, run_up

pytestmark = pytest.mark.system

#: a preload window of 55.5 to 56.8 kN (the shipped 53 to 59 kN): some runs end outside it
TIGHT = {
    "force_min_n = 53000.0": "force_min_n = 55500.0",
    "force_max_n = 59000.0": "force_max_n = 56800.0",
}


def test_overlay_of_real_runs_found_by_id(tmp_path: Path) -> None:
    station = write_station(tmp_path, replacements=TIGHT)
    run_up(station, runs=3)
    results = read_recordings(tmp_path / "recordings")["boltwatch/st1/results"]
    verdicts = {result["run_id"]: result["result"] for result in results}
    assert len(verdicts) == 3
    first, *others = sorted(verdicts)

    out = tmp_path / "overlay.png"
    command = [sys.executable, "-m", "services.cli", "inspect", "--config", str(station),
               "--overlay", *map(str, others), "--reference", str(first),
               "--align", "first-slip", "--out", str(out)]  # fmt: skip
    drawn = subprocess.run(command, capture_output=True, text=True, cwd=REPO, check=False)
    assert drawn.returncode == 0, drawn.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    listed = ", ".join(f"{run} {verdicts[run]}" for run in (first, *others))
    assert f"wrote {out}: 3 runs ({listed}), aligned at first stick-slip event" in drawn.stdout

    folder = tmp_path / "recordings"
    runs = [read_overlay_run(str(r), find_run_files(folder, "st1", r), r) for r in verdicts]
    overlay = build_overlay(runs[1:], runs[0], parse_alignment("first-slip"))
    reference = overlay.series[0]
    for run, series in zip(runs, overlay.series, strict=True):
        assert series.verdict == verdicts[run.run_id] and series.aligned
        assert len(series.torque_nm) > 1000 and series.force_n is not None
        # each run's first stick-slip peak lands on the reference's, in angle and in time
        peak = align_index(run, parse_alignment("first-slip"))
        ref_peak = align_index(runs[0], parse_alignment("first-slip"))
        assert peak is not None and ref_peak is not None
        assert series.angle_deg[peak] == pytest.approx(reference.angle_deg[ref_peak])
        assert series.time_s[peak] == pytest.approx(reference.time_s[ref_peak])
        assert series.torque_nm[peak] == pytest.approx(run.events[0].peak_torque_nm)
    (windows,) = overlay.windows
    assert (windows.torque_min_nm, windows.torque_max_nm) == (180.0, 240.0)
    assert (windows.angle_min_deg, windows.angle_max_deg) == (35.0, 65.0)
    assert (windows.force_min_n, windows.force_max_n) == (55500.0, 56800.0)
