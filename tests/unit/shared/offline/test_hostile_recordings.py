"""Readers of a recordings folder past hostile files: ``report`` (from the recordings and from
the store), ``results rebuild``, the overlay, and a FIFO given as a recording.

Real files in a real folder (:mod:`tests.support.hostile_recordings`): a file
cut to 10 bytes, an empty one, a FIFO named like a run file, payloads on a
results channel that are no result, results of ±1e308 Nm. Each file that
cannot be read is named and skipped, each payload or result refused is
counted, and the report is written from the rest.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

from services.cli.main import main
from shared.contract import JudgedFigure, TighteningResult, encode
from shared.quality import implausible
from shared.results import ResultsStore, store_target
from tests.support import factories
from tests.support.hostile_recordings import (
    DAY_NS,
    GOOD_RUNS,
    WRONG_PAYLOADS,
    cut,
    fifo_beside,
    good_folder,
    good_result,
    write_payload_file,
    write_result_file,
)
from tests.support.live_recorder import write_station_file
from tests.support.retention_files import store, write_run_file

ABSURD_NM = (1e308, -1e308)
#: never dialled: report, results and inspect open no zenoh session
CONNECT = ["tcp/127.0.0.1:7447"]


def _absurd(run_id: int, torque_nm: float) -> TighteningResult:
    figure = JudgedFigure(torque_nm, 180.0, 240.0, "high")
    return factories.result(
        run_id, time_ns=DAY_NS + run_id * 10**9, final_torque_nm=figure, result="NOK"
    )


@pytest.fixture
def hostile(tmp_path: Path) -> tuple[Path, Path, list[Path]]:
    """The station file, its recordings folder and the files not readable: 12 good runs, of
    which run 1 cut to 10 bytes and run 2 emptied; a FIFO; run 20's file holding the four
    wrong payloads and a good result; runs 21 and 22 of ±1e308 Nm."""
    folder = tmp_path / "recordings"
    files = good_folder(folder)
    unreadable = [cut(files[0], 10), cut(files[1], 0)]
    fifo_beside(files[2], 99)
    write_payload_file(folder, 20, [*WRONG_PAYLOADS.values(), encode(good_result(20))])
    for run_id, torque_nm in zip((21, 22), ABSURD_NM, strict=True):
        write_result_file(folder, _absurd(run_id, torque_nm))
    station = write_station_file(tmp_path / "station.toml", folder, connect=CONNECT)
    return station, folder, unreadable


def _run(capsys: pytest.CaptureFixture[str], *arguments: str) -> tuple[int, str, str]:
    status = main(list(arguments))
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_report_from_a_hostile_folder_skips_refuses_and_counts(
    hostile: tuple[Path, Path, list[Path]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    station, _, unreadable = hostile
    out = tmp_path / "out"
    args = ["report", "--config", str(station), "--out", str(out), "--from-recordings"]
    status, printed, error = _run(capsys, *args)
    assert status == 0, error
    assert "Traceback" not in error
    kept = GOOD_RUNS - len(unreadable) + 1  # and run 20's good result
    assert f"program 1 (M14 to 56 kN): {kept} runs" in printed
    for path in unreadable:  # each named, once
        assert sum(str(path) in line and "skipped" in line for line in error.splitlines()) == 1
    assert "no MCAP data (empty file)" in error and "st1_run99_" not in error  # FIFO: not opened
    refused = [line for line in error.splitlines() if "refused" in line]
    assert len(refused) == len(WRONG_PAYLOADS) + len(ABSURD_NM)
    assert sum("final torque 1e+308 Nm" in line or "-1e+308" in line for line in refused) == 2
    assert any("value is nan" in line for line in refused)
    counts = "files not readable, skipped: 2; results and payloads refused: 6"
    assert counts in printed
    assert counts in (out / "report.html").read_text()
    assert (out / "report.png").read_bytes().startswith(b"\x89PNG")


def test_report_from_the_store_refuses_absurd_results(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "recordings"
    results = [good_result(n) for n in range(1, 7)]
    results += [_absurd(n, torque) for n, torque in zip((7, 8), ABSURD_NM, strict=True)]
    results.append(factories.result(9, time_ns=DAY_NS + 9 * 10**9, events=2_000_000))
    store(store_target(folder, None), results, folder / "st1" / "some.mcap")
    station = write_station_file(tmp_path / "station.toml", folder, connect=CONNECT)
    out = tmp_path / "out"
    status, printed, error = _run(capsys, "report", "--config", str(station), "--out", str(out))
    assert status == 0, error
    assert "from the results store" in printed and "program 1 (M14 to 56 kN): 6 runs" in printed
    assert "results and payloads refused: 3" in printed
    assert "2000000 stick-slip events, expected at most 1000000" in error


def test_results_rebuild_stores_every_readable_result(
    hostile: tuple[Path, Path, list[Path]], capsys: pytest.CaptureFixture[str]
) -> None:
    _, folder, unreadable = hostile
    status, printed, error = _run(capsys, "results", "rebuild", "--recordings", str(folder))
    assert status == 0, error
    for path in unreadable:
        assert sum(str(path) in line and "skipped" in line for line in error.splitlines()) == 1
    refused = [line for line in error.splitlines() if "refused" in line]
    assert len(refused) == len(WRONG_PAYLOADS) + len(ABSURD_NM)
    assert sum("final torque 1e+308 Nm" in line or "-1e+308" in line for line in refused) == 2
    stored = GOOD_RUNS - len(unreadable) + 1  # the absurd ones are no result
    assert re.search(rf"2 not readable, skipped; 6 refused\): {stored} results", printed), printed
    with ResultsStore(store_target(folder, None), create=False) as opened:
        assert ("st1", 20) in opened.verdicts([("st1", 20)])  # beside the wrong payloads
    status, printed, _ = _run(capsys, "results", "rebuild", "--recordings", str(folder))
    assert "0 results" in printed  # the file with refused payloads was read whole: not again


def test_rebuild_results_and_report_agree_on_what_is_a_result(
    hostile: tuple[Path, Path, list[Path]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """What ``results rebuild`` stores, ``results`` lists and ``report`` counts, from the store
    and from the files: the same results, the same absurd ones refused in the same words."""
    station, folder, unreadable = hostile
    kept = GOOD_RUNS - len(unreadable) + 1
    status, printed, error = _run(capsys, "results", "rebuild", "--recordings", str(folder))
    assert status == 0, error
    rebuilt = sorted(line.split("refused ", 1)[1] for line in error.splitlines() if "(tool" in line)
    assert len(rebuilt) == len(ABSURD_NM) and f": {kept} results, {kept} new" in printed

    status, printed, error = _run(capsys, "results", "--recordings", str(folder), "--csv")
    assert status == 0 and len(printed.splitlines()) == 1 + kept  # the header, each result
    listed = sorted(line.split("refused ", 1)[1] for line in error.splitlines() if "(tool" in line)
    assert listed == rebuilt

    reports = {}
    for source in ([], ["--from-recordings"]):
        out = tmp_path / f"report{len(source)}"
        args = ["report", "--config", str(station), "--out", str(out), *source]
        status, printed, error = _run(capsys, *args)
        assert status == 0, error
        assert printed.startswith(f"{kept} results (from ") and f": {kept} runs" in printed
        reports[len(source)] = sorted(
            line.split("refused ", 1)[1] for line in error.splitlines() if "(tool" in line
        )
    assert reports[0] == reports[1] == rebuilt


def test_overlay_skips_a_part_that_cannot_be_read(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "recordings"
    write_run_file(folder, 5, DAY_NS, [good_result(5)], samples=40, rerun_bytes=0)
    broken = cut(write_run_file(folder, 5, DAY_NS + 10**9, samples=40, part=2, rerun_bytes=0), 10)
    station = write_station_file(tmp_path / "station.toml", folder, connect=CONNECT)
    target = tmp_path / "overlay.png"
    args = ["inspect", "--config", str(station), "--overlay", "5", "--out", str(target)]
    status, printed, error = _run(capsys, *args)
    assert status == 0, error
    assert str(broken) in error and "skipped" in error and "wrote" in printed
    assert target.read_bytes().startswith(b"\x89PNG")


@pytest.mark.timeout(30)  # before, opening the FIFO waited for a writer for ever
@pytest.mark.parametrize("command", ["inspect", "export", "recover"])
def test_a_fifo_named_like_a_recording_is_refused_at_once(
    tmp_path: Path, command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    fifo = tmp_path / "run.mcap"
    os.mkfifo(fifo)
    status, _, error = _run(capsys, command, str(fifo))
    assert status == 2
    assert error.count("\n") == 1 and f"{fifo}: a FIFO, not a recording" in error


@pytest.mark.parametrize(
    ("changes", "why"),
    [
        ({"final_torque_nm": JudgedFigure(1.01e6, None, None, "not_judged")}, "final torque"),
        ({"final_angle_deg": JudgedFigure(50.0, 35.0, 2e7, "ok")}, "final angle window max"),
        ({"final_force_n": JudgedFigure(-2e9, None, None, "low")}, "final preload -2e+09"),
        ({"events": 1_000_001}, "1000001 stick-slip events"),
        ({"process_intensity": -1.0}, "process intensity -1"),
        ({"process_intensity": 2e21}, "process intensity 2e+21"),
    ],
)
def test_absurd_figures_are_named(changes: dict[str, object], why: str) -> None:
    refused = implausible(factories.result(1, **changes))
    assert refused is not None and refused.startswith(why)


def test_figures_at_the_bounds_are_measurements() -> None:
    edge = factories.result(
        1,
        final_torque_nm=JudgedFigure(-1e6, -1e6, 1e6, "ok"),
        final_angle_deg=JudgedFigure(1e7, None, None, "not_judged"),
        final_force_n=JudgedFigure(1e9, None, None, "not_judged"),
        events=1_000_000,
        process_intensity=1e21,
    )
    assert implausible(edge) is None
    assert implausible(factories.result(1, events=None, process_intensity=None)) is None


@pytest.mark.parametrize("source", [[], ["--from-recordings"]])
def test_a_result_ending_a_nanosecond_from_a_bound_is_in_the_range_it_is_in(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], source: list[str]
) -> None:
    """``--since`` and ``--until`` hold to the nanosecond, from the store (integer
    nanoseconds in SQL) and from the files alike (a float of seconds since 1970 holds about a
    quarter of a microsecond): each run is its own program, so the report says which."""
    folder = tmp_path / "recordings"
    since_ns, until_ns = DAY_NS + 10**9, DAY_NS + 5 * 10**9  # 08:00:01 and 08:00:05
    ended = {1: since_ns - 1, 2: since_ns, 3: until_ns - 1, 4: until_ns}
    for run_id, time_ns in ended.items():
        result = factories.result(
            run_id, time_ns=time_ns, program_id=run_id, program_name=f"P{run_id}"
        )
        write_result_file(folder, result)
    station = write_station_file(tmp_path / "station.toml", folder, connect=CONNECT)
    assert main(["results", "rebuild", "--config", str(station)]) == 0
    window = ["--since", "2026-03-02T08:00:01", "--until", "2026-03-02T08:00:05"]
    capsys.readouterr()
    status, printed, _ = _run(capsys, "results", "--config", str(station), *window, "--csv")
    assert status == 0 and len(printed.splitlines()) == 3  # the header, runs 3 and 2
    out = str(tmp_path / "out")
    args = ["report", "--config", str(station), "--out", out, *window, *source]
    status, printed, error = _run(capsys, *args)
    assert status == 0, error
    counted = sorted(int(n) for n in re.findall(r"^program (\d+) \(", printed, re.MULTILINE))
    assert counted == [2, 3]
