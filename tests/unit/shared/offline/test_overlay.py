"""``boltwatch inspect --overlay``: runs written by the recorder's own MCAP sink, found by id
in a station's recordings or by path, aligned, drawn with their windows and verdicts."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from services.cli.main import main
from shared.contract import JudgedFigure, Sample, TighteningResult, encode
from shared.offline.overlay import (
    Overlay,
    build_figure,
    build_overlay,
    find_run_files,
    parse_alignment,
    read_overlay_cycle,
    read_overlay_run,
    run_colours,
)
from shared.offline.overlay.overlay_plot import legend_label
from shared.recordings import classify, file_path
from shared.recordings.mcap import McapSink
from tests.support import factories
from tests.support.station_files import write_station

T0_NS = 1_790_000_000_000_000_000
MS_NS = 1_000_000
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _result(
    run_id: int, program_id: int, verdict: str, windows: tuple[float | None, ...]
) -> TighteningResult:
    torque_min, torque_max, angle_min, angle_max, force_min, force_max = windows
    return factories.result(
        run_id,
        program_id=program_id,
        program_name=f"program {program_id}",
        time_ns=T0_NS,
        final_torque_nm=JudgedFigure(1.0, torque_min, torque_max, "ok"),
        final_angle_deg=JudgedFigure(1.0, angle_min, angle_max, "ok"),
        final_force_n=JudgedFigure(1.0, force_min, force_max, "ok" if verdict == "OK" else "low"),
        result=verdict,
        nok_reasons="" if verdict == "OK" else "preload low: 1 N, window 2 to 3 N",
        events=1,
        process_intensity=1.0,
    )


def _record(
    folder: Path,
    run_id: int,
    torque_nm: np.ndarray,
    angle_deg: np.ndarray,
    force_n: np.ndarray | None,
    first_event: int | None,
    result: TighteningResult | None,
) -> Path:
    """One run as the recorder files it: samples, an event, the result, in its day folder."""
    t0_ns = T0_NS + run_id * 10**9
    path = file_path(folder, "st1", run_id, t0_ns)
    path.parent.mkdir(parents=True, exist_ok=True)
    with McapSink(path, {}, run_id, t0_ns) as sink:
        for n, torque in enumerate(torque_nm):
            force = None if force_n is None else float(force_n[n])
            sample = Sample("st1", run_id, n, t0_ns + n * MS_NS, float(torque),
                            float(angle_deg[n]), force, time_s=n / 1e3)  # fmt: skip
            sink.write(classify("boltwatch/st1/samples", encode(sample), t0_ns + n * MS_NS))
        if first_event is not None:
            event = factories.event(
                run_id,
                1,
                time_ns=t0_ns + first_event * MS_NS,
                time_s=first_event / 1e3,
                peak_torque_nm=float(torque_nm[first_event]),
            )
            sink.write(classify("boltwatch/st1/events", encode(event), t0_ns + first_event * MS_NS))
        if result is not None:
            sink.write(classify("boltwatch/st1/results", encode(result), t0_ns + 300 * MS_NS))
    return path


N = np.arange(200, dtype=np.float64)
WINDOWS_1 = (150.0, 250.0, 10.0, 20.0, 15000.0, 19000.0)
WINDOWS_2 = (120.0, None, 12.0, 18.0, None, 16000.0)


@pytest.fixture
def station(tmp_path: Path) -> Path:
    """A station file whose recordings hold runs 11 (OK, program 1), 12 (NOK, program 2,
    later and at other angles), 13 (torque only, never above 80 Nm, no event)."""
    path = write_station(tmp_path)
    folder = tmp_path / "recordings"
    _record(folder, 11, 2.0 * N, 0.1 * N + 0.5, 100.0 * N, 50, _result(11, 1, "OK", WINDOWS_1))
    _record(folder, 12, 2.0 * N - 20.0, 0.1 * N, 90.0 * N, 70, _result(12, 2, "NOK", WINDOWS_2))
    _record(folder, 13, 0.4 * N, 0.2 * N, None, None, None)
    return path


def _overlay(station: Path, align: str, reference: int | None = 11) -> Overlay:
    folder = station.parent / "recordings"
    runs = [read_overlay_run(str(i), find_run_files(folder, "st1", i), i) for i in (12, 13)]
    ref = read_overlay_run("11", find_run_files(folder, "st1", 11), 11) if reference else None
    return build_overlay(runs, ref, parse_alignment(align))


def test_torque_alignment_shifts_each_run_onto_the_reference(station: Path) -> None:
    overlay = _overlay(station, "torque:100")
    reference, late, low = overlay.series
    assert (reference.run_id, reference.reference, late.run_id, low.run_id) == (11, True, 12, 13)
    # run 11 reaches 100 Nm at sample 50 (5.5 deg, 0.050 s), run 12 at sample 60 (6.0 deg, 0.060 s)
    np.testing.assert_allclose(reference.angle_deg, 0.1 * N + 0.5)
    np.testing.assert_allclose(late.angle_deg, 0.1 * N - 0.5)
    np.testing.assert_allclose(late.time_s, N / 1e3 - 0.010, atol=1e-12)
    assert late.aligned and late.verdict == "NOK" and late.program_id == 2
    assert not low.aligned and low.note == "not aligned: never reaches 100 Nm"
    np.testing.assert_allclose(low.angle_deg, 0.2 * N)  # left where it was
    assert low.force_n is None and low.verdict == "no result"


def test_first_slip_and_start_alignments(station: Path) -> None:
    _, late, low = _overlay(station, "first-slip").series
    # first events: run 11 at sample 50 (5.5 deg), run 12 at sample 70 (7.0 deg)
    assert late.shift_angle_deg == pytest.approx(-1.5) and late.shift_time_s == pytest.approx(-0.02)
    assert low.note == "not aligned: has no stick-slip event"
    _, late, low = _overlay(station, "start").series
    assert late.shift_angle_deg == pytest.approx(0.5) and late.shift_time_s == 0.0
    assert low.aligned and low.shift_angle_deg == pytest.approx(0.5)


def test_windows_of_each_program_in_its_runs_frame(station: Path) -> None:
    overlay = _overlay(station, "first-slip")
    first, second = overlay.windows
    assert (first.program_id, first.from_run, first.angle_min_deg, first.force_max_n) == (
        1, 11, 10.0, 19000.0,
    )  # fmt: skip
    assert (second.program_id, second.from_run, second.torque_max_nm) == (2, 12, None)
    assert (second.angle_min_deg, second.angle_max_deg) == pytest.approx((10.5, 16.5))


def test_figure_draws_the_series_and_the_nok_run_stands_out(station: Path) -> None:
    overlay = _overlay(station, "torque:100")
    figure = build_figure(overlay)
    angle_torque = figure.axes[0]
    drawn = {
        round(float(np.asarray(line.get_xdata())[0]), 6): np.asarray(line.get_ydata())
        for line in angle_torque.lines
    }
    for series in overlay.series:
        np.testing.assert_allclose(drawn[round(float(series.angle_deg[0]), 6)], series.torque_nm)
    colours = run_colours(overlay)
    assert colours[11] == "black"
    red, _green, blue, _alpha = colours[12]
    assert red > 0.9 and blue < 0.1  # NOK: from the reds
    assert colours[13][2] > 0.5  # not NOK: from the blues
    assert len(figure.axes) == 4  # torque and preload, over angle and over time


def test_command_by_id_and_by_path(
    station: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "overlay.png"
    path_12 = find_run_files(tmp_path / "recordings", "st1", 12)[0]
    status = main(["inspect", "--config", str(station), "--overlay", str(path_12), "13",
                   "--reference", "11", "--align", "torque:100", "--out", str(out)])  # fmt: skip
    assert status == 0
    assert out.read_bytes()[:8] == PNG_MAGIC
    captured = capsys.readouterr()
    assert "3 runs (11 OK, 12 NOK, 13 no result)" in captured.out
    assert captured.err.strip() == (
        "boltwatch inspect: warning: run 13 never reaches 100 Nm: drawn unaligned "
        "(dotted, from its own start)"
    )


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["--overlay", "11", "99"], "run 99: not found, no st1_run99_*.mcap in the day folders of"),
        (["--overlay", "12", "--reference", "13", "--align", "torque:100"],
         "reference run 13 never reaches 100 Nm: no point to align the runs on"),
        (["--overlay", "13", "--align", "first-slip"],
         "none of the runs (13) reaches the alignment point (first stick-slip event)"),
        (["--overlay", "11", "--align", "torque:-3"], "--align 'torque:-3': expected start,"),
        (["--overlay", "11", "--out", "x.svg"], "the overlay is written as PNG"),
        (["--reference", "11"], "give a recording (RUN.mcap) to draw, or --overlay RUN..."),
        (["x.mcap", "--overlay", "11"], "--overlay takes its runs after it"),
    ],
)  # fmt: skip
def test_errors_are_one_line_exit_2(
    station: Path, arguments: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["inspect", "--config", str(station), *arguments]) == 2
    err = capsys.readouterr().err
    assert err.startswith("boltwatch inspect: ") and message in err and err.count("\n") == 1


def test_a_run_without_samples_is_refused(
    station: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    empty = _record(tmp_path / "recordings", 14, N[:0], N[:0], None, None, None)
    assert main(["inspect", "--config", str(station), "--overlay", "11", "14"]) == 2
    err = capsys.readouterr().err
    assert f"boltwatch inspect: run 14: no samples in {empty}: nothing to draw" in err


def _record_cycle(folder: Path, sync_id: int, spindles: int) -> Path:
    """One multi-spindle cycle as the recorder files it: every spindle's run in one file,
    named by the first; each spindle a little stiffer than the one before."""
    t0_ns = T0_NS + sync_id * 10**9
    path = file_path(folder, "st1", sync_id, t0_ns)
    path.parent.mkdir(parents=True, exist_ok=True)
    with McapSink(path, {}, sync_id, t0_ns) as sink:
        for k in range(spindles):
            run_id = sync_id + k
            for n, torque in enumerate((2.0 + 0.1 * k) * N):
                sample = Sample("st1", run_id, n, t0_ns + n * MS_NS, float(torque),
                                float(0.1 * n), 100.0 * n, time_s=n / 1e3)  # fmt: skip
                sink.write(classify("boltwatch/st1/samples", encode(sample), t0_ns + n * MS_NS))
        for k in range(spindles):
            result = _result(sync_id + k, 1, "OK", WINDOWS_1)
            result = dataclasses.replace(result, spindle=k + 1, sync_id=sync_id)
            sink.write(classify("boltwatch/st1/results", encode(result), t0_ns + 300 * MS_NS))
    return path


def test_a_cycles_spindles_are_overlaid_from_its_file_or_any_of_its_runs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    station = write_station(tmp_path)
    folder = tmp_path / "recordings"
    cycle_file = _record_cycle(folder, 500, 4)
    target = tmp_path / "cycle.png"
    assert main(["inspect", "--overlay", str(cycle_file), "--cycle", "--out", str(target)]) == 0
    printed = capsys.readouterr().out
    assert "4 runs (500 OK, 501 OK, 502 OK, 503 OK)" in printed
    assert target.read_bytes().startswith(PNG_MAGIC)
    runs = read_overlay_cycle("502", [cycle_file], 502)
    assert [(run.run_id, run.result.spindle if run.result else None) for run in runs] == [
        (500, 1), (501, 2), (502, 3), (503, 4),
    ]  # fmt: skip
    overlay = build_overlay(runs, None, parse_alignment("start"))
    assert [series.spindle for series in overlay.series] == [1, 2, 3, 4]
    assert "spindle 3" in legend_label(overlay.series[2])
    # spindle 3's run by its id: its cycle's file is named by spindle 1's run; the results
    # store names it
    from shared.results import ResultsStore, StoreTarget, stored_result

    with ResultsStore(StoreTarget(sqlite_path=folder / "results.sqlite")) as store:
        result = dataclasses.replace(_result(502, 1, "OK", WINDOWS_1), spindle=3, sync_id=500)
        store.add([stored_result(result, "", str(cycle_file), "box", 1)])
    status = main(
        ["inspect", "--overlay", "502", "--cycle", "--config", str(station), "--out", str(target)]
    )
    assert status == 0 and "4 runs" in capsys.readouterr().out
