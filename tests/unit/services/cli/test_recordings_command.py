"""``boltwatch recordings prune``: --dry-run says what would go and deletes nothing; without it
the same files go, and only they; the store is SQLite beside the recordings or a real
PostgreSQL; errors are one line."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from services.cli.main import main
from shared.results import store_target
from tests.support.live_recorder import write_station_file
from tests.support.retention_files import DAY_NS, run_result, store, write_run_file

RETENTION = {"keep_days": 30, "keep_nok_days": 365}


def _prune(capsys: pytest.CaptureFixture[str], station: Path, *more: str) -> tuple[int, str, str]:
    status = main(["recordings", "prune", "--config", str(station), *more])
    out = capsys.readouterr()
    return status, out.out, out.err


def _listed(out: str, verb: str) -> list[Path]:
    """The files of the lines ``<verb>  <path>  ...``."""
    return [Path(line.split("  ")[1]) for line in out.splitlines() if line.startswith(f"{verb}  ")]


@pytest.fixture(params=["sqlite", "postgresql"])
def database(request: pytest.FixtureRequest) -> str | None:
    return None if request.param == "sqlite" else str(request.getfixturevalue("postgres_url"))


def test_dry_run_lists_what_the_real_run_deletes(
    tmp_path: Path, database: str | None, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "recordings"
    recorder = {} if database is None else {"results_database": database}
    station = write_station_file(
        tmp_path / "station.toml",
        folder,
        listen=["tcp/127.0.0.1:7447"],
        recorder=recorder,
        retention=RETENTION,
    )
    target = store_target(folder, database)
    now_ns = time.time_ns()
    paths = {}
    for run_id, days_ago, verdict, stored in [
        (1, 400, "NOK", True),  # past keep_nok_days
        (2, 100, "NOK", True),  # NOK within keep_nok_days: kept
        (3, 40, "OK", True),  # past keep_days
        (4, 40, "OK", False),  # its result not stored: kept
        (5, 35, None, False),  # no result (aborted): its age decides
        (6, 3, "OK", True),  # within keep_days
    ]:
        results = [] if verdict is None else [run_result(run_id, verdict)]
        paths[run_id] = write_run_file(folder, run_id, now_ns - days_ago * DAY_NS, results)
        if stored:
            store(target, results, paths[run_id])

    status, out, err = _prune(capsys, station, "--dry-run")
    assert status == 0, err
    would = _listed(out, "would delete")
    assert would == [paths[1], paths[3], paths[5]]  # oldest first
    assert _listed(out, "kept") == [paths[4]]
    assert all(path.exists() and path.with_suffix(".rrd").exists() for path in paths.values())
    assert "would delete 3 files" in out
    assert "2 files" in out and "older than keep_days (30 days)" in out
    assert "1 file" in out and "NOK, older than keep_nok_days (365 days)" in out
    assert "results not in the store ('boltwatch results rebuild' stores them)" in out

    status, out, err = _prune(capsys, station)
    assert status == 0 and err == ""
    assert _listed(out, "deleted") == would
    for path in paths.values():
        assert path.exists() is (path not in would)
        assert path.with_suffix(".rrd").exists() is (path not in would)
    assert "deleted 3 files" in out

    status, out, _ = _prune(capsys, station, "--dry-run")
    assert status == 0 and _listed(out, "would delete") == [] and "nothing to delete" in out


def test_no_rule_deletes_nothing(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = tmp_path / "recordings"
    station = write_station_file(tmp_path / "station.toml", folder, listen=["tcp/127.0.0.1:7447"])
    old = write_run_file(folder, 1, time.time_ns() - 4000 * DAY_NS)
    status, out, _ = _prune(capsys, station)
    assert status == 0 and "every curve kept for ever" in out and "nothing deleted" in out
    assert old.exists()


def test_no_store_and_disagreeing_files_are_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "recordings"
    station = write_station_file(
        tmp_path / "a.toml", folder, listen=["tcp/127.0.0.1:7447"], retention=RETENTION
    )
    old = write_run_file(folder, 1, time.time_ns() - 400 * DAY_NS, [run_result(1)])
    status, _, err = _prune(capsys, station)
    assert status == 2 and err.count("\n") == 1
    assert err.startswith("boltwatch recordings prune: no results store at ")
    assert old.exists()

    other = write_station_file(
        tmp_path / "b.toml", folder, listen=["tcp/127.0.0.1:7447"], retention={"keep_days": 7}
    )
    other.write_text(other.read_text().replace('id = "st1"', 'id = "st2"', 1))
    status = main(["recordings", "prune", "--config", str(station), str(other)])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1
    assert f"{other}: retention.keep_days: 7 differs from 30 of {station}" in err
