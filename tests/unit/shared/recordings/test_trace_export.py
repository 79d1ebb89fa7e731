"""Export of a recording's samples to the trace CSV, from whole and from damaged files."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from services.cli.main import main
from shared.contract import Sample, encode, read_trace
from shared.errors import InputError
from shared.recordings import classify
from shared.recordings.mcap import McapSink, export_trace

T0_NS = 1_700_000_000_000_000_000
MS_NS = 1_000_000


def write(sink: McapSink, run_id: int, first: int, count: int) -> None:
    for n in range(first, first + count):
        force = None if n == 0 else 1000.0 + n
        sample = Sample("st1", run_id, n, T0_NS + n * MS_NS, 10.0 + n, 0.5 * n, force)
        sink.write(classify("boltwatch/st1/samples", encode(sample), T0_NS + n * MS_NS + 7))


def recording(tmp_path: Path) -> Path:
    with McapSink(tmp_path / "run3.mcap", {}, 3, T0_NS) as sink:
        write(sink, 3, 0, 50)
        sink.write(classify("boltwatch/st1/samples", b"garbage", T0_NS))
        write(sink, 4, 0, 5)
    return sink.path


def test_the_run_with_most_samples_is_exported(tmp_path: Path) -> None:
    report = export_trace(recording(tmp_path))
    assert (report.run_id, report.rows, report.complete) == (3, 50, True)
    trace = read_trace(report.target)
    assert report.target == tmp_path / "run3.csv"
    np.testing.assert_allclose(trace.time_s, np.arange(50) * 1e-3)
    np.testing.assert_allclose(trace.torque_nm, 10.0 + np.arange(50))
    assert math.isnan(trace.force_n[0]) and trace.force_n[1] == 1001.0


def test_a_run_can_be_chosen_and_unknown_runs_are_named(tmp_path: Path) -> None:
    path = recording(tmp_path)
    assert export_trace(path, tmp_path / "r4.csv", run_id=4).rows == 5
    with pytest.raises(InputError, match=r"no samples of run 9 \(runs in the file: 3, 4\)"):
        export_trace(path, tmp_path / "r9.csv", run_id=9)


def test_a_damaged_file_exports_what_is_readable(tmp_path: Path) -> None:
    with McapSink(tmp_path / "live.mcap", {}, 3, T0_NS) as sink:
        write(sink, 3, 0, 40)
        sink.flush()
        write(sink, 3, 40, 40)
        shutil.copyfile(sink.path, tmp_path / "killed.mcap")
    assert main(["export", str(tmp_path / "killed.mcap")]) == 0
    assert len(read_trace(tmp_path / "killed.csv")) == 40


def test_cli_recover_and_export_name_the_bad_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bogus = tmp_path / "bogus.mcap"
    bogus.write_text("hello")
    assert main(["export", str(bogus)]) == 2
    assert main(["recover", str(bogus)]) == 2
    err = capsys.readouterr().err.splitlines()
    magic = "expected the MCAP magic b'\\x89MCAP0\\r\\n')"
    assert err == [
        f"boltwatch export: {bogus}: not an MCAP file (byte 0: b'hello', {magic}",
        f"boltwatch recover: {bogus}: not an MCAP file (byte 0: b'hello', {magic}",
    ]
    path = recording(tmp_path)
    assert main(["recover", str(path), "--out", str(tmp_path / "copy.mcap")]) == 0
    assert "recovered 56 messages on 2 channels" in capsys.readouterr().out
