"""``boltwatch import`` and a controller's clock: any duration is one file, the impossible refused.

Copies of a shipped real run with their times or identity changed: an hour
(and more) is still one file; times no recording can hold (1e12 s, before
1970, past 2262) and a clock that goes back are refused with one line naming
the file, the key and the index, and the rest of the batch is imported.
"""

from __future__ import annotations

import itertools
import json
from pathlib import Path
from typing import Any

import pytest

from services.cli.main import main
from shared.offline.controller_import import read_controller_run
from shared.recordings.mcap import RecordingScan
from tests.support.paths import PROJECT_REAL_RUNS

SOURCE = PROJECT_REAL_RUNS / "Ch_000001596334.json"  # 4 steps, 624 samples
GOOD = PROJECT_REAL_RUNS / "Ch_000001621524.json"


def variant(folder: Path, name: str, cycle: int, change: Any) -> Path:
    """A copy of SOURCE as run ``cycle``, with ``change(document)`` applied."""
    document = json.loads(SOURCE.read_text())
    document["cycle"] = cycle
    change(document)
    path = folder / f"{name}.json"
    path.write_text(json.dumps(document))
    return path


def times(document: dict[str, Any], step: int) -> list[float]:
    values: list[float] = document["tightening steps"][step]["graph"]["time values"]
    return values


def import_(paths: list[Path], recordings: Path) -> int:
    return main(["import", *map(str, paths), "--recordings", str(recordings), "--no-rerun"])


def test_a_run_lasting_past_an_hour_is_one_complete_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    def hours_long(document: dict[str, Any]) -> None:
        times(document, 3)[-2] = 3600.0  # the one-hour rotation of a live file
        times(document, 3)[-1] = 7300.5

    late = variant(tmp_path, "late", 11, hours_long)
    recordings = tmp_path / "recordings"
    assert import_([late, GOOD], recordings) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[-1].startswith("imported 2 of 2 runs")
    (path,) = recordings.glob("cs351/*/cs351_run11_*")  # no _part2, no .rrd, nothing else
    scan = RecordingScan(path)
    assert sum(1 for _ in scan.messages("/samples")) == len(read_controller_run(late))
    assert scan.complete

    assert import_([late], recordings) == 0  # the finished file is recognised
    assert "already in" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("name", "change", "expected"),
    [
        (
            "far_future_time",
            lambda d: times(d, 3).__setitem__(5, 1e12),
            "tightening steps[3].graph.time values[5]: 1000000000000.0 s after 'date' "
            "2022-09-05 13:43:39 is past 2262-04-11 23:47:16 UTC",
        ),
        (
            "before_1970",
            lambda d: d.__setitem__("date", "1969-12-31 23:59:59"),
            "'date': 1969-12-31 23:59:59 is before 1970-01-01 00:00:00 UTC",
        ),
        (
            "after_2262",
            lambda d: d.__setitem__("date", "2263-01-01 00:00:00"),
            "'date': 2263-01-01 00:00:00 is after 2262-04-11 23:47:16 UTC",
        ),
        (
            "ends_past_2262",
            lambda d: (
                d.__setitem__("date", "2262-04-11 23:47:00"),
                times(d, 3).__setitem__(-1, 17.0),
            ),
            "tightening steps[3].graph.time values[72]: 17.0 s after 'date' 2262-04-11 23:47:00",
        ),
        (
            "before_its_date",
            lambda d: times(d, 0).__setitem__(0, -0.5),
            "tightening steps[0].graph.time values[0]: -0.5 s is before the run's 'date'",
        ),
        (
            "negative_cycle",
            lambda d: d.__setitem__("cycle", -5),
            "'cycle': expected a number from 0 up, got -5",
        ),
        (
            "cycle_beyond_64_bits",
            lambda d: d.__setitem__("cycle", 2**64),
            "'cycle': 18446744073709551616 is too large",
        ),
    ],
)
def test_times_and_ids_no_recording_can_hold_are_refused_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str, change: Any, expected: str
) -> None:
    bad = variant(tmp_path, name, 12, change)
    recordings = tmp_path / "recordings"

    assert import_([bad, GOOD], recordings) == 2

    captured = capsys.readouterr()
    (line,) = captured.err.splitlines()
    assert line.startswith(f"boltwatch import: {bad}: ")
    assert expected in line, line
    assert captured.out.splitlines()[-1] == (
        f"imported 1 of 2 runs into {recordings}, 0 already there, 1 refused"
    )
    (written,) = recordings.glob("cs351/*/*")  # the good run only: no run-5, no 1960 folder
    assert "_run1621524_" in written.name
    assert [p.name for p in recordings.glob("cs351/*")] == ["2024-09-04"]


def test_a_clock_that_goes_back_is_refused_naming_where_and_how_often(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    def swapped(document: dict[str, Any]) -> None:
        values = times(document, 1)
        values[10], values[11] = values[11], values[10]

    def restarting(document: dict[str, Any]) -> None:  # each step's clock from 0
        for step in range(4):
            first = times(document, step)[0]
            document["tightening steps"][step]["graph"]["time values"] = [
                t - first for t in times(document, step)
            ]

    back = variant(tmp_path, "back", 21, swapped)
    restart = variant(tmp_path, "restart", 22, restarting)
    recordings = tmp_path / "recordings"

    assert import_([back, restart, GOOD], recordings) == 2

    captured = capsys.readouterr()
    back_line, restart_line = captured.err.splitlines()
    assert back_line.startswith(
        f"boltwatch import: {back}: tightening steps[1].graph.time values[11]: "
        "time goes back from 0.1284 s to 0.1272 s (back once in the run)"
    ), back_line
    assert restart_line.startswith(
        f"boltwatch import: {restart}: tightening steps[1].graph.time values[0]: "
        "step 1 restarts the clock at 0.0 s after 0.1152 s (back 3 times in the run, "
        "3 times where a step starts)"
    ), restart_line
    assert "refused" in back_line and "repeated times are fine" in back_line
    assert captured.out.splitlines()[-1].endswith("0 already there, 2 refused")
    assert not list(recordings.glob("cs351/*/cs351_run2[12]_*"))


def test_the_sample_a_step_repeats_from_the_previous_one_is_not_flagged(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    document = json.loads(SOURCE.read_text())
    steps = [step["graph"] for step in document["tightening steps"]]
    for previous, step in itertools.pairwise(steps):  # the real file repeats it
        for key in ("time values", "torque values", "angle values"):
            assert step[key][0] == previous[key][-1]

    assert import_([SOURCE], tmp_path / "recordings") == 0
    captured = capsys.readouterr()
    assert captured.err == ""
    assert captured.out.splitlines()[-1].endswith("0 refused")
