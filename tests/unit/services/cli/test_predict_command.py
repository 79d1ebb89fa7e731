"""``boltwatch import`` and ``boltwatch predict`` end to end, real controller runs included."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from services.cli.main import main
from shared.contract import read_trace, write_trace
from tests.support.paths import DBC_FILE, HANDBOOK_REAL_RUNS, STATION_FILE
from tests.support.synthetic_runs import staircase

REAL_RUNS = HANDBOOK_REAL_RUNS


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


@pytest.mark.parametrize("value", ["inf", "-inf", "nan", "0", "-3", "1e400"])
@pytest.mark.parametrize("option", ["--target-torque", "--target-force"])
def test_a_target_that_is_not_a_finite_positive_number_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], option: str, value: str
) -> None:
    path = tmp_path / "run.csv"
    write_trace(path, staircase(torque_noise_nm=0.2, force_noise_n=30.0).csv_rows())
    assert main(["predict", str(path), f"{option}={value}"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"{option} must be a finite number > 0" in err[0]


def strict_json(text: str) -> object:
    """json.loads that refuses NaN and Infinity (they are not JSON)."""

    def refuse(constant: str) -> object:
        raise ValueError(f"not JSON: {constant}")

    return json.loads(text, parse_constant=refuse)


@pytest.mark.parametrize("absurd", [1e300, 1e308, -1e308])
def test_an_absurd_sample_is_counted_and_the_output_stays_json(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], absurd: float
) -> None:
    """One 1e300 sample silenced the run and --summary printed Infinity."""
    rows = staircase(torque_noise_nm=0.2, force_noise_n=30.0).csv_rows()
    clean, damaged = tmp_path / "clean.csv", tmp_path / "damaged.csv"
    write_trace(clean, rows)
    t, _, a, f = rows[500]
    write_trace(damaged, [*rows[:500], (t, absurd, a, f), *rows[501:]])
    outputs = []
    for path in (clean, damaged):
        assert main(["predict", str(path), "--target-force", "30400", "--summary"]) == 0
        captured = capsys.readouterr()
        records = [strict_json(line) for line in captured.out.splitlines()]
        summary = strict_json(captured.err.strip().splitlines()[-1])
        outputs.append((records, summary))
    (clean_records, clean_summary), (records, summary) = outputs
    assert summary["input"]["implausible"] == 1  # type: ignore[index]
    assert [r for r in records if r["type"] == "stop"] == [  # type: ignore[index]
        r
        for r in clean_records
        if r["type"] == "stop"  # type: ignore[index]
    ]
    assert summary["events"] == pytest.approx(clean_summary["events"], abs=1)  # type: ignore[index]


def test_predict_takes_the_sensor_range_of_a_dbc(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """With the station's DBC, a torque its 24-bit signal cannot carry is implausible."""
    rows = staircase(torque_noise_nm=0.2, force_noise_n=30.0).csv_rows()
    path = tmp_path / "run.csv"
    t, _, a, f = rows[300]
    write_trace(path, [*rows[:300], (t, 9000.0, a, f), *rows[301:]])
    dbc = DBC_FILE
    assert (
        main(["predict", str(path), "--target-force", "30400", "--summary", "--dbc", str(dbc)]) == 0
    )
    summary = strict_json(capsys.readouterr().err.strip().splitlines()[-1])
    assert summary["input"]["implausible"] == 1  # type: ignore[index]
    assert main(["predict", str(path), "--target-force", "1", "--dbc", str(tmp_path)]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_predict_decides_as_a_station_decides_its_program(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--config --program: the station's targets, limits, speed and joint (live = offline)."""
    trace = tmp_path / "run.csv"
    write_trace(trace, staircase(torque_noise_nm=0.2, force_noise_n=30.0).csv_rows())
    station = STATION_FILE
    assert main(["predict", str(trace), "--config", str(station), "--program", "2"]) == 0
    # program 2's target is 40 kN: this staircase never gets there, and no limit fires
    assert [r for r in lines(capsys.readouterr().out) if r["type"] == "stop"] == []
    command = ["predict", str(trace), "--config", str(station), "--program", "2"]
    assert main([*command, "--target-force", "30400"]) == 0  # an option replaces the file's
    (stop,) = [r for r in lines(capsys.readouterr().out) if r["type"] == "stop"]
    assert stop["reason"] in ("plateau_closest", "target_reached")
    assert main(["predict", str(trace), "--config", str(station)]) == 2
    assert "--config needs --program ID" in capsys.readouterr().err
    assert main(["predict", str(trace), "--config", str(station), "--program", "9"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no program 9" in err[0] and "known: 1, 2" in err[0]
