"""``boltwatch import`` and ``boltwatch predict`` end to end, real controller runs included."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from services.cli.main import main
from shared.trace import read_trace, write_trace
from tests.unit.predictor.synthetic import staircase

REAL_RUNS = Path(__file__).resolve().parents[3].parent / "shared/data/cs351-real-runs"


def lines(text: str) -> list[dict[str, object]]:
    return [json.loads(line) for line in text.splitlines() if line]


def test_predict_prints_events_and_one_stop(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "run.csv"
    write_trace(path, staircase(torque_noise_nm=0.2, force_noise_n=30.0).csv_rows())
    assert main(["predict", str(path), "--target-force", "30400"]) == 0
    records = lines(capsys.readouterr().out)
    stops = [r for r in records if r["type"] == "stop"]
    assert [s["reason"] for s in stops] == ["plateau_closest"]
    assert sum(r["type"] == "event" for r in records) > 20
    assert all("time_s" in r for r in records)


def test_predict_bad_input_is_one_line_and_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["predict", str(tmp_path / "missing.csv"), "--target-force", "1"]) == 2
    assert "missing.csv: file not found" in capsys.readouterr().err
    bad = tmp_path / "bad.csv"
    bad.write_text("time_s,torque_nm,angle_deg,force_n\n0.0,abc,0,\n")
    assert main(["predict", str(bad), "--target-torque", "1"]) == 2
    assert "line 2" in capsys.readouterr().err
    assert main(["predict", str(bad)]) == 2


def test_import_truncated_json_names_the_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    broken = tmp_path / "broken.json"
    broken.write_text('{"tightening steps": [{"graph": {"time values": [0.0, 0.1')
    assert main(["import", str(broken), "--out-dir", str(tmp_path / "out")]) == 2
    assert "broken.json" in capsys.readouterr().err


@pytest.mark.skipif(not REAL_RUNS.is_dir(), reason="real CS351 runs not beside the checkout")
def test_real_runs_import_and_predict_torque_only(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    runs = sorted(REAL_RUNS.glob("*.json"))
    assert len(runs) == 10
    assert main(["import", *map(str, runs), "--out-dir", str(tmp_path)]) == 0
    capsys.readouterr()
    for run in runs:
        csv = tmp_path / f"{run.stem}.csv"
        trace = read_trace(csv)
        assert not trace.has_force and len(trace) > 500
        assert main(["predict", str(csv), "--target-torque", "1.4"]) == 0
        records = lines(capsys.readouterr().out)
        stops = [r for r in records if r["type"] == "stop"]
        assert len(stops) <= 1
        for stop in stops:  # only in the final tightening step, not while thread forming
            assert stop["reason"] in ("plateau_closest", "target_reached")
            assert float(stop["time_s"]) > 0.5 * float(trace.time_s[-1])  # type: ignore[arg-type]
