"""``boltwatch report`` over MCAP recordings written by the recorder's own sink.

The figures the report prints and embeds are checked against numpy computed
here from the values written; windows two-sided, one-sided and absent; the
range, program and tool filters; no result in range (one line, exit 2).
"""

from __future__ import annotations

import dataclasses
import re
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pytest

from services.cli.main import main
from shared.contract import FigureStatus, JudgedFigure, TighteningResult, encode
from shared.quality import c4, control_chart
from shared.recordings import classify, file_path
from shared.recordings.mcap import McapSink
from tests.support import factories
from tests.support.live_recorder import write_station_file

DAY1_NS = int(datetime(2026, 3, 2, 8, 0, tzinfo=UTC).timestamp() * 1e9)
DAY2_NS = int(datetime(2026, 3, 3, 8, 0, tzinfo=UTC).timestamp() * 1e9)
TORQUE = (180.0, 240.0)  # program 1: a two-sided torque window
ANGLE_MIN = 35.0  # program 1: a one-sided angle window (no maximum)
FORCE = (53000.0, 59000.0)


def _figure(value: float | None, low: float | None, high: float | None) -> JudgedFigure:
    status: FigureStatus = "ok"
    if value is not None and low is not None and value < low:
        status = "low"
    if value is not None and high is not None and value > high:
        status = "high"
    return JudgedFigure(value, low, high, status if low or high else "not_judged")


def _result(
    run_id: int, time_ns: int, program: int, tool: int, values: tuple[float, ...]
) -> TighteningResult:
    torque, angle, force, intensity, events = values
    windowed = program == 1
    t = _figure(torque, *(TORQUE if windowed else (None, None)))
    a = _figure(angle, ANGLE_MIN if windowed else None, None)
    f = _figure(force, *(FORCE if windowed else (None, None)))
    judged = (("torque", t), ("angle", a), ("preload", f))
    # as the predictor words them: the kind, then the figures
    reasons = [
        f"{name} {j.status}: {j.value:.1f}" for name, j in judged if j.status in ("low", "high")
    ]
    return factories.result(
        run_id,
        tool_id=tool,
        program_id=program,
        program_name=f"P{program}",
        time_ns=time_ns,
        final_torque_nm=t,
        final_angle_deg=a,
        final_force_n=f,
        result="NOK" if reasons else "OK",
        nok_reasons="; ".join(reasons),
        stop_reason="plateau_closest" if run_id % 3 else None,
        events=int(events),
        process_intensity=intensity,
    )


def _write_run(folder: Path, result: TighteningResult) -> None:
    path = file_path(folder, "st1", result.run_id, result.time_ns)
    path.parent.mkdir(parents=True, exist_ok=True)
    summary = factories.summary(
        result.run_id,
        tool_id=result.tool_id,
        program_id=result.program_id,
        target_torque_nm=None,
        reached_force_n=result.final_force_n.value,
        reached_torque_nm=result.final_torque_nm.value or 0.0,
        error_pct=0.1,
        events=result.events or 0,
        stop_reason=result.stop_reason,
        process_intensity=result.process_intensity or 0.0,
        samples=10,
        started_ns=result.time_ns - 10**9,
        ended_ns=result.time_ns,
    )
    with McapSink(path, {"station": {"station": "st1"}}, result.run_id, result.time_ns) as sink:
        sink.write(classify("boltwatch/st1/results", encode(result), result.time_ns))
        sink.write(classify("boltwatch/st1/runs", encode(summary), result.time_ns))


@pytest.fixture
def recorded(tmp_path: Path) -> tuple[Path, list[TighteningResult]]:
    """25 runs of program 1 (tool 7; some NOK) and 12 of program 2 (tool 8, no windows),
    over two days; returns the station file and the results in the order written."""
    recordings = tmp_path / "recordings"
    rng = np.random.default_rng(19)
    results = []
    for n in range(37):
        program, tool = (1, 7) if n < 25 else (2, 8)
        day = DAY1_NS if n % 2 else DAY2_NS
        values = (
            rng.normal(210.0, 12.0), rng.normal(47.0, 5.0), rng.normal(56000.0, 1500.0),
            rng.normal(1e6, 4e4), float(rng.integers(38, 44)),
        )  # fmt: skip
        results.append(_result(n + 1, day + n * 10**9, program, tool, values))
        _write_run(recordings, results[-1])
    station = write_station_file(
        tmp_path / "station.toml", recordings, connect=["tcp/127.0.0.1:7447"]
    )
    results.sort(key=lambda result: result.time_ns)
    return station, results


def _cpk(values: list[float], low: float | None, high: float | None) -> float:
    mean, sigma = np.mean(values), np.std(values, ddof=1)
    sides = [(high - mean) / (3 * sigma)] if high is not None else []
    return float(min([*sides, *([(mean - low) / (3 * sigma)] if low is not None else [])]))


def _report(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    status = main(["report", *args])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def _printed_cpk(out: str, program: int, figure: str) -> str:
    block = out.split(f"program {program} (")[1].split("\nprogram ", maxsplit=1)[0]
    line = next(line for line in block.splitlines() if line.strip().startswith(figure))
    return line


def test_report_figures_match_numpy(
    recorded: tuple[Path, list[TighteningResult]],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    station, results = recorded
    out = tmp_path / "out"
    status, printed, _ = _report(["--config", str(station), "--out", str(out)], capsys)
    assert status == 0, printed
    one = [result for result in results if result.program_id == 1]
    torque = [r.final_torque_nm.value for r in one if r.final_torque_nm.value is not None]
    angle = [r.final_angle_deg.value for r in one if r.final_angle_deg.value is not None]
    noks = sum(1 for r in one if r.result == "NOK")
    assert noks > 0, "the fixture must make some NOK runs"
    assert f"program 1 (P1): 25 runs, NOK {noks} ({100 * noks / 25:.1f} %)" in printed
    line = _printed_cpk(printed, 1, "final torque")
    assert f"Cpk {_cpk(torque, *TORQUE):.2f}" in line
    assert f"mean {np.mean(torque):.6g}" in re.sub(r"\s+", " ", line)
    # one-sided: the Cpk of the lower side only, and no Cp
    line = _printed_cpk(printed, 1, "final angle")
    assert f"Cpk {_cpk(angle, ANGLE_MIN, None):.2f}" in line and "Cp –" in line
    assert "window ≥ 35" in line
    # no window at all: not computed, said
    assert "Cpk not computed (no window)" in _printed_cpk(printed, 2, "final torque")
    assert "Cpk not computed (no window)" in _printed_cpk(printed, 1, "process intensity")
    # the Pareto: each reason counted once per run, most frequent first
    reasons = [
        reason.split(":")[0] for r in one if r.nok_reasons for reason in r.nok_reasons.split("; ")
    ]
    most = max(reasons.count(reason) for reason in reasons)
    printed_top = re.search(r"NOK reasons: ([a-z ]+) \((\d+)\)", printed)
    assert printed_top is not None and int(printed_top[2]) == most
    assert reasons.count(printed_top[1]) == most
    page = (out / "report.html").read_text()
    assert f"{_cpk(torque, *TORQUE):.2f}" in page and "not computed: no window" in page
    assert "data:image/png;base64," in page
    assert not re.search(r"(src|href)=\"?https?:", page), "the page must need no internet"
    assert (out / "report.png").read_bytes().startswith(b"\x89PNG\r\n\x1a\n")


def test_report_filters_range_program_and_tool(
    recorded: tuple[Path, list[TighteningResult]],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    station, results = recorded
    out = str(tmp_path / "out")
    args = ["--config", str(station), "--out", out, "--until", "2026-03-02"]
    status, printed, _ = _report(args, capsys)
    day1 = [r for r in results if r.time_ns < DAY2_NS]
    assert status == 0
    assert f"{len(day1)} results" in printed
    args = ["--config", str(station), "--out", out, "--since", "2026-03-03", "--program", "2"]
    status, printed, _ = _report(args, capsys)
    day2_p2 = [r for r in results if r.time_ns >= DAY2_NS and r.program_id == 2]
    assert status == 0 and f"program 2 (P2): {len(day2_p2)} runs" in printed
    assert "program 1 (" not in printed
    status, printed, _ = _report(["--config", str(station), "--out", out, "--tool", "8"], capsys)
    assert status == 0 and "program 1 (" not in printed and "program 2 (P2): 12 runs" in printed


@pytest.mark.parametrize("source", [[], ["--from-recordings"]])
def test_the_program_and_tool_a_result_can_have_can_be_asked_for(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], source: list[str]
) -> None:
    """Ids are the contract's 64-bit ones (a controller's parameter set and tool serial,
    imported): what the store holds and ``results --program`` finds, ``report`` finds too."""
    recordings = tmp_path / "recordings"
    program, tool = 2**40 + 3, 2**62
    for n in range(1, 4):
        values = (210.0 + n, 47.0, 56000.0, 1e6, 40.0)
        _write_run(recordings, _result(n, DAY1_NS + n * 10**9, program, tool, values))
    station = write_station_file(
        tmp_path / "station.toml", recordings, connect=["tcp/127.0.0.1:7447"]
    )
    assert main(["results", "rebuild", "--config", str(station)]) == 0
    assert main(["results", "--config", str(station), "--program", str(program)]) == 0
    out = str(tmp_path / "out")
    args = ["--config", str(station), "--out", out, "--program", str(program), "--tool", str(tool)]
    capsys.readouterr()
    status, printed, error = _report([*args, *source], capsys)
    assert status == 0, error
    assert f"program {program} (P{program}): 3 runs" in printed


def test_no_result_in_range_is_one_line_and_status_2(
    recorded: tuple[Path, list[TighteningResult]],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    station, _ = recorded
    args = ["--config", str(station), "--out", str(tmp_path / "o"), "--since", "2027-01-01"]
    status, printed, error = _report(args, capsys)
    assert status == 2 and printed == ""
    assert error.count("\n") == 1 and error.startswith("boltwatch report: no tightening results")
    assert not (tmp_path / "o").exists()
    with pytest.raises(SystemExit) as stopped:
        main(["report", "--config", str(station), "--since", "March"])
    assert stopped.value.code == 2
    assert "expected a date YYYY-MM-DD" in capsys.readouterr().err


def test_control_chart_limits_match_numpy() -> None:
    values = np.random.default_rng(5).normal(100.0, 3.0, size=23)
    chart = control_chart(values, 5)
    assert chart is not None and chart.spread == "R" and chart.left_out == 3
    groups = values[:20].reshape(4, 5)
    r_bar = np.ptp(groups, axis=1).mean()
    assert chart.centre == pytest.approx(groups.mean())
    assert chart.mean_limits == pytest.approx(
        (groups.mean() - 0.577 * r_bar, groups.mean() + 0.577 * r_bar)
    )
    assert chart.spread_limits == pytest.approx((0.0, 2.114 * r_bar))
    big = control_chart(values, 11)  # X̄/s above 10
    assert big is not None and big.spread == "s"
    s_bar = values[:22].reshape(2, 11).std(axis=1, ddof=1).mean()
    assert big.spread_centre == pytest.approx(s_bar)
    assert c4(11) == pytest.approx(0.9754, abs=1e-4) and c4(25) == pytest.approx(0.9896, abs=1e-4)
    assert control_chart(values[:4], 5) is None


def test_a_multi_spindle_station_is_reported_per_spindle_as_per_program(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Each spindle's runs have their statistics (X̄/R, Cpk) after the program's, on the
    terminal, the page (with the spindles side by side) and the picture."""
    recordings = tmp_path / "recordings"
    rng = np.random.default_rng(3)
    for cycle in range(10):
        for spindle in (1, 2):
            run = 1000 + 2 * cycle + spindle
            values = (
                rng.normal(210.0 + 5 * spindle, 4.0), rng.normal(47.0, 3.0),
                rng.normal(56000.0, 900.0), rng.normal(1e6, 4e4), 40.0,
            )  # fmt: skip
            result = _result(run, DAY1_NS + cycle * 10**9 + spindle, 1, 6 + spindle, values)
            _write_run(recordings, dataclasses.replace(result, spindle=spindle, sync_id=1000))
    station = write_station_file(
        tmp_path / "station.toml", recordings, connect=["tcp/127.0.0.1:7447"]
    )
    out = tmp_path / "out"
    status, printed, _ = _report(["--config", str(station), "--out", str(out)], capsys)
    assert status == 0, printed
    assert "program 1 (P1): 20 runs" in printed
    assert "program 1 (P1) spindle 1: 10 runs" in printed
    assert "program 1 (P1) spindle 2: 10 runs" in printed
    page = (out / "report.html").read_text()
    assert "its spindles side by side" in page and "Program 1: P1, spindle 2" in page
