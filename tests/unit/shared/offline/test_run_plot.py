"""``boltwatch inspect`` draws a recorded run into a PNG."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from services.cli.main import main
from shared.config import load_joint
from shared.contract import Prediction, Sample, StickSlipEvent, StopDecision, encode
from shared.offline.post_mortem import build_figure, plateau_bars, prediction_errors, read_run
from shared.recordings import classify, flatten
from shared.recordings.mcap import McapSink
from tests.support import factories
from tests.support.paths import JOINT_5_2

T0_NS = 1_700_000_000_000_000_000
MS_NS = 1_000_000


def test_inspect_writes_a_png(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with McapSink(tmp_path / "run1.mcap", {}, 1, T0_NS) as sink:
        for n in range(200):
            sample = Sample("st1", 1, n, T0_NS + n * MS_NS, n % 50 * 1.0, n * 0.1, 1e4 + n * 10)
            sink.write(classify("boltwatch/st1/samples", encode(sample), T0_NS + n * MS_NS))
        for j, n in enumerate((49, 99, 149), start=1):
            event = StickSlipEvent(
                "st1", 1, j, T0_NS + n * MS_NS, n / 1e3, 49.0, 0.0, 49.0, 1e4 + n * 10,
                500.0, 0.05, 20.0, None, None, None, 0.1, 0.1 * j,
            )  # fmt: skip
            sink.write(classify("boltwatch/st1/events", encode(event), T0_NS + n * MS_NS))
        decision = StopDecision(
            "st1", 1, T0_NS + 190 * MS_NS, 0.19, "plateau_closest", "", 40.0, 1.2e4, None, 0
        )
        sink.write(classify("boltwatch/st1/decision", encode(decision), T0_NS + 190 * MS_NS))
    assert main(["inspect", str(sink.path)]) == 0
    png = tmp_path / "run1.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "200 samples, 3 stick-slip events" in capsys.readouterr().out


JOINT_FILE = JOINT_5_2
PEAKS = (100, 130, 158, 184, 208)  # sample numbers of the stick-slip peaks


def _synthetic_run(path: Path, *, with_force: bool, metadata: dict[str, dict[str, str]]) -> Path:
    """A run of 250 samples whose peaks at PEAKS carry 1st-3rd predictions of the next ones."""
    with McapSink(path, metadata, 1, T0_NS) as sink:
        for n in range(250):
            force = 1e4 + n * 40.0 if with_force else None
            sample = Sample("st1", 1, n, T0_NS + n * MS_NS, 40.0 + n * 0.3, n * 0.03, force)
            sink.write(classify("boltwatch/st1/samples", encode(sample), T0_NS + n * MS_NS))
        for j, n in enumerate(PEAKS, start=1):
            period = None if j == 1 else (n - PEAKS[j - 2]) / 1e3
            later = [
                Prediction(h, PEAKS[j - 1 + h] / 1e3 + 0.001, 40.0 + PEAKS[j - 1 + h] * 0.3 - 0.5,
                           1e4 + PEAKS[j - 1 + h] * 40.0 - 100.0 if with_force else None)
                for h in (1, 2, 3) if j - 1 + h < len(PEAKS)
            ]  # fmt: skip
            plateau = 1e4 + (n - 10) * 40.0 if with_force else None
            event = StickSlipEvent(
                "st1", 1, j, T0_NS + n * MS_NS, n / 1e3, 40.0 + n * 0.3, 38.0 + n * 0.3, 2.0,
                plateau, 800.0 if with_force and j > 1 else None, period,
                1 / period if period else None, 3.0 if period else None, 1e4 if period else None,
                5.0, 1.0, 1.0, later,
            )  # fmt: skip
            sink.write(classify("boltwatch/st1/events", encode(event), T0_NS + n * MS_NS))
        decision = StopDecision(
            "st1", 1, T0_NS + 230 * MS_NS, 0.23, "plateau_closest", "", 109.0, 1.9e4, None, 0
        )
        sink.write(classify("boltwatch/st1/decision", encode(decision), T0_NS + 230 * MS_NS))
    return path


PANEL_TITLES = (
    "Fig. 10 (top)",
    "Fig. 10 (bottom)",
    "Fig. 13",
    "Fig. 14",
    "Fig. 15",
    "K1",
    "K2",
    "K3",
    "Fig. 22: prediction error, peak torque",
    "Fig. 22: prediction error, plateau force",
    "Fig. 22: prediction error, time",
    "Fig. 23: relative prediction error, peak torque",
    "Fig. 23: relative prediction error, plateau force",
    "Fig. 23: relative prediction error, time",
)


def _titles(figure: Any) -> list[str]:
    return [axis.get_title() for axis in figure.axes]


def test_report_has_the_papers_panels_with_bounds(tmp_path: Path) -> None:
    joint = flatten(load_joint(JOINT_FILE).model_dump(mode="json"))
    metadata = {"joint": joint, "program": {"motor_speed_rad_s": "0.5", "target_force_n": "2e4"}}
    run = read_run(_synthetic_run(tmp_path / "run.mcap", with_force=True, metadata=metadata))
    figure = build_figure(run)
    titles = _titles(figure)
    assert len(titles) == len(PANEL_TITLES)
    for expected, title in zip(PANEL_TITLES, titles, strict=True):
        assert title.startswith(expected)
    caption = figure.get_suptitle()
    assert "model time t = run time" in caption and "t(F_1 = 13.6 kN)" in caption
    torque_labels = figure.axes[0].get_legend_handles_labels()[1]
    assert any(label.startswith("T_max") for label in torque_labels)
    # each 1st/2nd/3rd prediction that a later event can be checked against, eqs. 61-63
    errors = prediction_errors(run.events)
    assert [(e.horizon, e.index) for e in errors] == [
        (1, 2), (1, 3), (1, 4), (1, 5), (2, 3), (2, 4), (2, 5), (3, 4), (3, 5),
    ]  # fmt: skip
    # measured − predicted: each prediction is 1 ms late and 300 N high (negative), 0.5 Nm low
    first = errors[0]
    assert first.time_error_s == pytest.approx(-0.001)
    assert first.torque_error_nm == pytest.approx(0.5)
    assert first.force_error_n == pytest.approx(-300.0)
    assert first.relative_time == pytest.approx(-0.001 / 0.030)
    error_axes = figure.axes[8:14]
    for axis, unit in zip(error_axes, ("Nm", "kN", "ms", "%", "%", "%"), strict=True):
        label = axis.get_ylabel()
        assert label.startswith("measured − predicted\n") and label.endswith(f"/ {unit}")
    time_ms = figure.axes[10].lines[0].get_ydata()  # the 1st predictions of t, in ms
    assert time_ms == pytest.approx([-1.0] * 4)


def _event(index: int, time_s: float, torque_nm: float, force_n: float, period_s: float | None,
           predictions: list[Prediction]) -> StickSlipEvent:  # fmt: skip
    return factories.event(
        1,
        index,
        time_ns=T0_NS + round(time_s * 1e9),
        time_s=time_s,
        peak_torque_nm=torque_nm,
        plateau_force_n=force_n,
        period_s=period_s,
        predictions=predictions,
    )


def test_every_error_is_measured_minus_predicted() -> None:
    # Event 1 predicts event 2 late, too high and too strong, and event 3 early, too low
    # and too weak: the first errors are all negative, the second all positive.
    late_high = Prediction(1, time_s=0.105, peak_torque_nm=52.0, plateau_force_n=10_300.0)
    early_low = Prediction(2, time_s=0.115, peak_torque_nm=57.0, plateau_force_n=10_800.0)
    events = [
        _event(1, 0.080, 45.0, 9_500.0, None, [late_high, early_low]),
        _event(2, 0.100, 50.0, 10_000.0, 0.020, []),
        _event(3, 0.120, 60.0, 11_000.0, 0.020, []),
    ]
    late, early = prediction_errors(events)
    assert (late.horizon, late.index, early.horizon, early.index) == (1, 2, 2, 3)
    assert late.time_error_s == pytest.approx(-0.005)
    assert late.torque_error_nm == pytest.approx(-2.0)
    assert late.force_error_n == pytest.approx(-300.0)
    assert late.relative_time == pytest.approx(-0.005 / 0.020)
    assert late.relative_torque == pytest.approx(-2.0 / 50.0)
    assert late.relative_force == pytest.approx(-300.0 / 10_000.0)
    assert early.time_error_s == pytest.approx(0.005)
    assert early.torque_error_nm == pytest.approx(3.0)
    assert early.force_error_n == pytest.approx(200.0)
    assert early.relative_time == pytest.approx(0.005 / 0.020)
    assert early.relative_torque == pytest.approx(3.0 / 60.0)
    assert early.relative_force == pytest.approx(200.0 / 11_000.0)


def test_plateaus_span_the_stick_phase_before_their_peak(tmp_path: Path) -> None:
    run = read_run(_synthetic_run(tmp_path / "run.mcap", with_force=True, metadata={}))
    bars = plateau_bars(run)
    assert [(round(start, 3), round(end, 3)) for _, start, end in bars] == [
        (0.07, 0.1), (0.1, 0.13), (0.13, 0.158), (0.158, 0.184), (0.184, 0.208),
    ]  # fmt: skip
    assert bars[1][0] == pytest.approx(1e4 + 120 * 40.0)


def test_torque_only_run_without_metadata_says_there_are_no_bounds(tmp_path: Path) -> None:
    run = read_run(_synthetic_run(tmp_path / "run.mcap", with_force=False, metadata={}))
    figure = build_figure(run)
    assert len(_titles(figure)) == len(PANEL_TITLES)
    caption = figure.get_suptitle()
    assert "No analytical bounds (no joint metadata" in caption
    assert "torque only" in caption
    notes = [text.get_text() for text in figure.axes[1].texts]
    assert notes == ["no preload force in this run (torque-only recording)"]
