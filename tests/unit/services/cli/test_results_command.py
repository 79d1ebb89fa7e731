"""``boltwatch results`` over real controller runs: imported as recordings, read into the
store by ``results rebuild`` (again: nothing twice, nothing read twice), then found by
their part (or plant: the station file's), as a table naming each run's recording, as CSV
and as JSON."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import pytest

from services.cli.main import main
from shared.recordings.mcap import RecordingScan
from tests.support.config_files import write_station
from tests.support.imported_runs import import_runs, recording_of
from tests.support.paths import PROJECT_REAL_RUNS

RUNS = sorted(PROJECT_REAL_RUNS.glob("Ch_*.json"))
#: two of the real runs tightened this part (their controller's "id code")
PART = "30000000008730"


@pytest.fixture
def recordings(tmp_path: Path) -> Path:
    folder = tmp_path / "recordings"
    assert import_runs(RUNS, folder) == 0
    return folder


def _results(capsys: pytest.CaptureFixture[str], *arguments: str) -> tuple[int, str, str]:
    status = main(["results", *arguments])
    out = capsys.readouterr()
    return status, out.out, out.err


def test_rebuild_then_find_a_parts_tightenings(
    recordings: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    status, _, err = _results(capsys, "--recordings", str(recordings))
    assert status == 2 and "no results store at" in err and "results rebuild" in err

    status, out, err = _results(capsys, "rebuild", "--recordings", str(recordings))
    assert status == 0, err
    assert "read 4 of 4 recordings" in out and "4 results, 4 new" in out
    assert "4 of 4 recordings" in err  # progress
    status, out, _ = _results(capsys, "rebuild", "--recordings", str(recordings))
    assert "read 0 of 4 recordings (4 read before, unchanged): 0 results, 0 new" in out

    status, out, _ = _results(capsys, "--recordings", str(recordings), "--part", PART)
    header, *rows = out.splitlines()
    assert status == 0 and header.startswith("ended (UTC)") and len(rows) == 2
    for row, run in zip(rows, ["1596339", "1596334"], strict=True):  # newest first
        assert f" {run} " in row and PART in row and " OK " in row
        recording = Path(row.split()[-1])
        assert recording == recording_of(recordings, PROJECT_REAL_RUNS / f"Ch_00000{run}.json")
        assert RecordingScan(recording).messages("/results")


def test_csv_and_json_have_every_column(
    recordings: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["results", "rebuild", "--recordings", str(recordings)]) == 0
    capsys.readouterr()
    _, out, _ = _results(capsys, "--recordings", str(recordings), "--csv")
    rows = list(csv.DictReader(io.StringIO(out)))
    assert len(rows) == 4
    assert {row["part_id"] for row in rows} == {PART, "40000000016001", "40000000016002"}
    assert all(row["source"] == "import" and row["result"] == "OK" for row in rows)
    _, out, _ = _results(capsys, "--recordings", str(recordings), "--json", "--limit", "1")
    (document,) = json.loads(out)
    assert document["part_id"] == "40000000016002" and document["steps"]
    assert Path(document["recording"]).is_file()


def test_the_station_files_plant_line_and_name_go_with_each_result(
    recordings: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``rebuild --config``: each result placed as its station file says; ``--plant``
    finds them, the table names the station with its name, CSV and JSON have all three."""
    station = write_station(recordings.parent, "")
    text = station.read_text().replace('folder = "../recordings"', f'folder = "{recordings}"')
    place = 'id = "cs351"\nplant = "North"\nline = "B"\nname = "Wheel nuts"'
    station.write_text(text.replace('id = "st1"', place))
    assert main(["results", "rebuild", "--config", str(station)]) == 0
    capsys.readouterr()
    status, out, _ = _results(capsys, "--config", str(station), "--plant", "South")
    assert status == 1 and out == ""
    status, out, _ = _results(capsys, "--config", str(station), "--plant", "North")
    header, *rows = out.splitlines()
    assert status == 0 and len(rows) == 4
    assert header.split()[2:5] == ["station", "plant", "line"]
    assert all(" cs351 (Wheel nuts)  North  B " in row for row in rows)
    _, out, _ = _results(capsys, "--config", str(station), "--csv", "--limit", "1")
    (row,) = csv.DictReader(io.StringIO(out))
    assert (row["station_name"], row["plant"], row["line"]) == ("Wheel nuts", "North", "B")
    _, out, _ = _results(capsys, "--config", str(station), "--json", "--limit", "1")
    (document,) = json.loads(out)
    assert (document["station_name"], document["plant"], document["line"]) == (
        "Wheel nuts",
        "North",
        "B",
    )


def test_nothing_matching_is_one_line_and_status_1(
    recordings: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["results", "rebuild", "--recordings", str(recordings)]) == 0
    capsys.readouterr()
    status, out, err = _results(capsys, "--recordings", str(recordings), "--nok")
    assert (status, out, err) == (1, "", "boltwatch results: no tightening matches\n")


def test_a_bad_database_url_names_the_option(capsys: pytest.CaptureFixture[str]) -> None:
    status, _, err = _results(capsys, "--database", "mysql://db/results")
    assert status == 2 and "--database: not a postgresql:// URL" in err
