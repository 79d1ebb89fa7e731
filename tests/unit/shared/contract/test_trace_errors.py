"""Bad CSV traces, for real files: one line naming the file, the line and what is wrong.

``boltwatch predict`` reads traces through :func:`shared.contract.trace.read_trace`; each bad
file ends it with exit status 2 and that one line on stderr.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from services.cli.main import main
from shared.contract import read_trace
from shared.errors import InputError

GOOD = "time_s,torque_nm,angle_deg,force_n\n0.000,1.0,0.1,100.0\n0.001,1.5,0.2,\n"

BAD = {
    "empty": ("", "empty file (expected the header time_s,torque_nm,angle_deg,force_n)"),
    "blank": ("\n\n", "empty file (expected the header time_s,torque_nm,angle_deg,force_n)"),
    "bad header": (
        "time,torque\n0.0,1.0\n",
        "line 1: expected the header time_s,torque_nm,angle_deg,force_n, got 'time,torque'",
    ),
    "non-numeric": (
        GOOD + "0.002,abc,0.3,1.0\n",
        "line 4: torque_nm (column 2) is not a number: 'abc'",
    ),
    "nan": (GOOD + "nan,1.0,0.3,1.0\n", "line 4: time_s (column 1) is not finite: 'nan'"),
    "empty cell": (GOOD + "0.002,1.0,,1.0\n", "line 4: angle_deg (column 3) is empty"),
    "truncated last line": (
        GOOD + "0.002,1.7",
        "line 4: the last line is cut off (2 of 4 columns, no newline at the end of the file)",
    ),
    "extra column": (GOOD + "0.002,1.0,0.3,1.0,9\n", "line 4: expected 4 columns, got 5"),
    "header only": ("time_s,torque_nm,angle_deg,force_n\n", "no samples after the header"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_a_bad_trace_names_file_line_and_problem(tmp_path: Path, case: str) -> None:
    text, expected = BAD[case]
    path = tmp_path / "trace.csv"
    path.write_text(text)
    with pytest.raises(InputError) as raised:
        read_trace(path)
    assert str(raised.value) == f"{path}: {expected}"


def test_binary_garbage_says_where(tmp_path: Path) -> None:
    path = tmp_path / "trace.csv"
    path.write_bytes(b"time_s,torque_nm,angle_deg,force_n\n\xff\xfe\x00")
    with pytest.raises(InputError, match=r"trace.csv: not a text file \(byte 35: "):
        read_trace(path)


def test_a_good_trace_reads(tmp_path: Path) -> None:
    path = tmp_path / "trace.csv"
    path.write_text(GOOD)
    trace = read_trace(path)
    assert len(trace) == 2 and trace.has_force


@pytest.mark.parametrize("case", ["empty", "bad header", "non-numeric", "truncated last line"])
def test_predict_ends_with_one_line_and_status_2(
    tmp_path: Path, case: str, capsys: pytest.CaptureFixture[str]
) -> None:
    text, expected = BAD[case]
    path = tmp_path / "trace.csv"
    path.write_text(text)
    assert main(["predict", str(path), "--target-force", "40000"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == f"boltwatch predict: {path}: {expected}\n"
