"""Live = offline: the station's decision is the one ``boltwatch predict`` makes on the recording.

``boltwatch up`` tightens a handful of runs with the
station's predictor on the acquisition's CAN thread (placement edge); each
run's recorded samples are exported (``boltwatch export``: the sample clock
the predictor decided on) and predicted again offline with the station's
own settings (``boltwatch predict --config --program``). Each live decision
must be the offline one: the same reason at the same sample. A run whose
recording lacks samples (the recorder missed some) is not a fair comparison
and is left out, counted; none is expected on loopback.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from shared.recordings.mcap import export_trace
from tests.support.router_process import boltwatch
from tests.support.station_files import write_station
from tests.support.station_up import read_recordings, run_up

pytestmark = pytest.mark.system

RUNS = 4
PROGRAM = 1


def offline_stop(trace: Path, station: Path) -> dict[str, object] | None:
    result = boltwatch(
        "predict", str(trace), "--config", str(station), "--program", str(PROGRAM),
        timeout_s=None, check=True,
    )  # fmt: skip
    records = [json.loads(line) for line in result.stdout.splitlines()]
    return next((r for r in records if r["type"] == "stop"), None)


def test_every_live_decision_is_the_offline_one(tmp_path: Path) -> None:
    station = write_station(tmp_path)  # the shipped file's placement: edge
    run_up(station, runs=RUNS)
    recordings = tmp_path / "recordings"
    messages = read_recordings(recordings)
    decisions = {d["run_id"]: d for d in messages["boltwatch/st1/decision"]}
    samples: dict[int, list[int]] = {}
    for sample in messages["boltwatch/st1/samples"]:
        samples.setdefault(sample["run_id"], []).append(sample["sequence"])
    compared = 0
    for run_id, decision in sorted(decisions.items()):
        assert sorted(samples[run_id]) == list(range(len(samples[run_id]))), run_id
        (mcap,) = recordings.rglob(f"st1_run{run_id}_*.mcap")
        trace = tmp_path / f"run{run_id}.csv"
        export_trace(mcap, trace, run_id)
        offline = offline_stop(trace, station)
        assert offline is not None, f"run {run_id}: no offline decision"
        assert offline["reason"] == decision["reason"], (run_id, offline, decision)
        assert offline["time_s"] == pytest.approx(decision["time_s"], abs=1e-9), run_id
        compared += 1
    assert compared == RUNS
