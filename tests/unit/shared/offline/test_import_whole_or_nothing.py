"""``boltwatch import`` writes each run whole or not at all, and a bad one never stops the batch.

Real faults: a file where a day folder must go, a file size limit in a child
process (EFBIG mid-write), what an import killed half way leaves behind (a
cut file, a ``_part2``, a hidden temporary of a dead process), a
recordings or CSV folder that is a file. Every run ends up complete under
its real name, or absent; the last line counts what happened; no traceback.
"""

from __future__ import annotations

import os
import resource
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from services.cli.main import main
from shared.recordings.mcap import McapSink, RecordingScan
from shared.wear import WearLedger
from tests.support.paths import PROJECT_REAL_RUNS, REPO

CLASS_1 = [PROJECT_REAL_RUNS / "Ch_000001596334.json", PROJECT_REAL_RUNS / "Ch_000001596339.json"]
CLASS_2 = [PROJECT_REAL_RUNS / "Ch_000001621524.json", PROJECT_REAL_RUNS / "Ch_000001621527.json"]
#: An MCAP of a class-1 run is about 38 kB, of a class-2 run 62-72 kB (no .rrd)
FILE_SIZE_LIMIT = 60_000


def visible_files(folder: Path) -> list[str]:
    return sorted(
        str(p.relative_to(folder))
        for p in folder.rglob("*")
        if p.is_file() and not p.name.startswith(".")
    )


def hidden_files(folder: Path) -> list[Path]:
    return [p for p in folder.rglob(".*") if p.is_file()]


def samples_in(path: Path) -> tuple[int, bool]:
    scan = RecordingScan(path)
    return sum(1 for _ in scan.messages("/samples")), scan.complete


def test_a_day_folder_that_cannot_be_made_fails_its_runs_only(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    recordings = tmp_path / "recordings"
    (recordings / "cs351").mkdir(parents=True)
    (recordings / "cs351" / "2024-09-04").write_text("not a folder")  # class 2's day

    status = main(["import", *map(str, CLASS_2 + CLASS_1), "--recordings", str(recordings)])

    assert status == 2
    captured = capsys.readouterr()
    errors = captured.err.splitlines()
    assert len(errors) == 2
    for source, line in zip(CLASS_2, errors, strict=True):
        assert line.startswith(f"boltwatch import: {source}: not written: "), line
        assert "2024-09-04" in line and "(EEXIST)" in line, line
    assert captured.out.splitlines()[-1] == (
        f"imported 2 of 4 runs into {recordings}, 0 already there, 0 refused, 2 not written"
    )
    written = [p for p in visible_files(recordings) if p.endswith(".mcap")]
    assert len(written) == 2 and all("2022-09-05" in p for p in written)
    assert hidden_files(recordings) == []
    with WearLedger(recordings / "wear.sqlite", read_only=True) as ledger:
        assert ledger.tool(955000040).runs == 2  # the runs not written are not counted


def import_in_child(*args: str, limit: int = FILE_SIZE_LIMIT) -> subprocess.CompletedProcess[str]:
    """``boltwatch import ARGS`` in a child whose files may not grow past ``limit`` bytes."""

    def limit_file_size() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return subprocess.run(
        [sys.executable, "-m", "services.cli", "import", *args],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=120,
        preexec_fn=limit_file_size,
        check=False,
    )


def test_a_file_that_hits_a_size_limit_mid_write_leaves_nothing_and_the_batch_goes_on(
    tmp_path: Path,
) -> None:
    recordings = tmp_path / "recordings"
    assert main(["import", str(CLASS_1[0]), "--recordings", str(recordings), "--no-rerun"]) == 0
    inputs = [str(path) for path in (*CLASS_2, *CLASS_1)]

    result = import_in_child(*inputs, "--recordings", str(recordings), "--no-rerun")

    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr
    errors = result.stderr.splitlines()
    assert len(errors) == 2
    for source, line in zip(CLASS_2, errors, strict=True):
        assert line.startswith(f"boltwatch import: {source}: not written: {recordings}/cs351/")
        assert ".mcap: File too large (EFBIG)" in line and ".importing" not in line, line
    assert result.stdout.splitlines()[-1] == (
        f"imported 1 of 4 runs into {recordings}, 1 already there, 0 refused, 2 not written"
    )
    files = visible_files(recordings)
    assert [p for p in files if p.endswith(".mcap")] == [
        "cs351/2022-09-05/cs351_run1596334_134339.mcap",
        "cs351/2022-09-05/cs351_run1596339_134728.mcap",
    ]
    assert hidden_files(recordings) == []  # no temporary left
    assert not (recordings / "cs351" / "2024-09-04").exists()  # nor the folder made for them
    for name in files:
        if name.endswith(".mcap"):
            assert samples_in(recordings / name)[1]

    csv_dir = tmp_path / "csv"  # the CSVs of the class-2 runs: 40.3 kB and 37.4 kB
    result = import_in_child(*inputs[:2], "--csv", str(csv_dir), limit=39_000)
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert "Ch_000001621524.csv: File too large (EFBIG)" in result.stderr
    assert sorted(p.name for p in csv_dir.iterdir()) == ["Ch_000001621527.csv"]  # 37 kB


def test_a_run_an_earlier_import_left_half_written_is_imported_again(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    recordings = tmp_path / "recordings"
    assert main(["import", str(CLASS_1[0]), "--recordings", str(recordings)]) == 0
    (mcap,) = recordings.glob("cs351/2022-09-05/*.mcap")
    whole = mcap.read_bytes()
    mcap.write_bytes(whole[: len(whole) // 2])  # cut, as a killed import left it
    part2 = mcap.with_name("cs351_run1596334_144339_part2.mcap")  # what the rotation bug left
    part2.write_bytes(whole[: len(whole) // 3])
    part2.with_suffix(".rrd").write_bytes(b"cut")
    # a temporary file of an import killed before it finished: no process has that pid
    leftover = mcap.with_name(f".{mcap.stem}.999999999.importing.mcap")
    leftover.write_bytes(whole[:100])
    capsys.readouterr()

    assert main(["import", str(CLASS_1[0]), "--recordings", str(recordings)]) == 0

    out = capsys.readouterr().out
    assert "already in" not in out
    assert f"replaced the unfinished {mcap.name}" in out
    assert f"replaced the unfinished {part2.name}" in out
    assert out.splitlines()[-1].startswith("imported 1 of 1 runs")
    assert visible_files(recordings / "cs351") == [
        "2022-09-05/boltwatch.rbl",
        "2022-09-05/cs351_run1596334_134339.mcap",
        "2022-09-05/cs351_run1596334_134339.rrd",
    ]
    assert hidden_files(recordings) == []
    assert samples_in(mcap) == (624, True)
    with WearLedger(recordings / "wear.sqlite", read_only=True) as ledger:
        assert ledger.tool(955000040).runs == 1


def test_a_live_recording_of_the_same_run_id_is_never_touched(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    recordings = tmp_path / "recordings"
    live = recordings / "cs351" / "2022-09-05" / "cs351_run1596334_134339.mcap"
    McapSink(live, {"station": {"station": "cs351"}}, 1596334, 0).close()  # no controller record
    before = live.read_bytes()

    assert main(["import", str(CLASS_1[0]), "--recordings", str(recordings), "--no-rerun"]) == 0

    assert live.read_bytes() == before
    beside = live.with_name("cs351_run1596334_134339_2.mcap")
    assert samples_in(beside) == (624, True)
    assert "already in" not in capsys.readouterr().out


def test_a_destination_that_is_a_file_is_one_line_and_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    a_file = tmp_path / "a_file"
    a_file.write_text("")
    source = str(CLASS_1[0])

    assert main(["import", source, "--csv", str(a_file)]) == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert line == f"boltwatch import: {a_file}: --csv: is a file, expected a folder"

    assert main(["import", source, "--recordings", str(a_file / "recordings")]) == 2
    captured = capsys.readouterr()
    (line,) = captured.err.splitlines()
    assert line == (
        f"boltwatch import: {a_file / 'recordings'}: recordings folder: cannot be made: "
        f"{a_file} is a file, not a folder"
    )
    assert "recover" not in captured.err and "retried" not in captured.err  # no live advice
    assert captured.out == ""

    csv_dir = tmp_path / "csv"
    (csv_dir / f"{CLASS_1[0].stem}.csv").mkdir(parents=True)  # a folder where the CSV goes
    shutil.copyfile(CLASS_1[1], tmp_path / CLASS_1[1].name)
    assert main(["import", source, str(tmp_path / CLASS_1[1].name), "--csv", str(csv_dir)]) == 2
    captured = capsys.readouterr()
    (line,) = captured.err.splitlines()
    assert line.startswith(f"boltwatch import: {source}: not written: ")
    assert "(EISDIR)" in line
    assert captured.out.splitlines()[-1] == (
        f"imported 1 of 2 runs as trace CSVs into {csv_dir}, 0 refused, 1 not written"
    )


def test_a_rerun_file_that_cannot_be_written_fails_its_run_whole(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    recordings = tmp_path / "recordings"
    day = recordings / "cs351" / "2022-09-05"
    # this process's temporary .rrd of the run is taken by a folder: Rerun cannot write it
    (day / f".cs351_run1596334_134339.{os.getpid()}.importing.rrd").mkdir(parents=True)

    assert main(["import", *map(str, CLASS_1), "--recordings", str(recordings)]) == 2

    captured = capsys.readouterr()
    (line,) = captured.err.splitlines()
    assert line.startswith(f"boltwatch import: {CLASS_1[0]}: not written: ")
    assert "cs351_run1596334_134339.rrd" in line and ".importing" not in line, line
    assert captured.out.splitlines()[-1].endswith(", 0 refused, 1 not written")
    assert [p for p in visible_files(recordings) if "1596334" in p] == []  # no .mcap either
    assert [p.name for p in day.glob("*.mcap")] == ["cs351_run1596339_134728.mcap"]
