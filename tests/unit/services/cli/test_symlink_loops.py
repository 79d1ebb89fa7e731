"""A recordings folder that is a symlink to itself, and one that holds symlink loops (a
station folder, a day folder and a run file, each a link to itself), met by every command
that walks a recordings folder: ``report`` (from the store and ``--from-recordings``),
``results`` and ``results rebuild`` (``--config`` and ``--recordings``), ``inspect
--overlay``, ``recordings prune`` (the retention policy), and the recorder (its start and
its catch-up). The folder itself: one line naming it, exit status 2, no traceback. A loop
inside it: skipped, named in one line, the rest read."""

from __future__ import annotations

import logging
import time
from pathlib import Path

import pytest

from services.cli.main import main
from shared.config import StationPlace, load_station
from shared.errors import ConfigError
from shared.recordings import file_path
from shared.results import ResultsQuery, ResultsStore, store_target
from tests.support import factories
from tests.support.hostile_recordings import DAY_NS, good_result
from tests.support.live_recorder import wait_until, write_station_file
from tests.support.retention_files import write_run_file

#: never dialled: these commands open no zenoh session
CONNECT = ["tcp/127.0.0.1:7447"]
LOOP = "is a symlink loop"


def _run(capsys: pytest.CaptureFixture[str], *arguments: str) -> tuple[int, str, str]:
    status = main(list(arguments))
    captured = capsys.readouterr()
    return status, captured.out, captured.err


@pytest.fixture
def looping(tmp_path: Path) -> tuple[Path, Path]:
    """A station file whose ``recorder.folder`` (relative, as the shipped one's) is a link
    to itself; the station file and the folder."""
    folder = tmp_path / "recordings"
    folder.symlink_to(folder.name)
    retention = {"keep_days": 1}
    station = write_station_file(
        tmp_path / "station.toml", Path("recordings"), connect=CONNECT, retention=retention
    )
    return station, folder


@pytest.fixture
def holding(tmp_path: Path) -> tuple[Path, Path, list[Path]]:
    """A station file whose recordings folder holds a good run (run 5 of st1) and three
    loops: station st2's folder, a day folder of st1, a run file of st1; the station file,
    the folder and the loops."""
    folder = tmp_path / "recordings"
    good = write_run_file(folder, 5, DAY_NS, [good_result(5)], samples=40, rerun_bytes=0)
    day = good.parent
    loops = [
        folder / "st2",
        day.with_name("2026-03-05"),
        file_path(folder, "st1", 99, DAY_NS + 3600 * 10**9),
    ]
    for loop in loops:
        loop.symlink_to(loop.name)
    station = write_station_file(
        tmp_path / "station.toml", folder, connect=CONNECT, retention={"keep_days": 1}
    )
    return station, folder, loops


#: each command, and how it names itself in its error line
COMMANDS = {
    "report": (["report", "--out", "{out}"], "report"),
    "report --from-recordings": (["report", "--from-recordings", "--out", "{out}"], "report"),
    "results": (["results"], "results"),
    "results rebuild": (["results", "rebuild"], "results"),
    "inspect --overlay": (["inspect", "--overlay", "5", "--out", "{out}/o.png"], "inspect"),
    "recordings prune": (["recordings", "prune", "--dry-run"], "recordings prune"),
}


@pytest.mark.parametrize("command", COMMANDS)
def test_a_recordings_folder_that_is_a_link_to_itself_is_one_line(
    looping: tuple[Path, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    command: str,
) -> None:
    station, folder = looping
    (tmp_path / "out").mkdir()
    arguments, label = COMMANDS[command]
    arguments = [argument.format(out=tmp_path / "out") for argument in arguments]
    status, printed, error = _run(capsys, *arguments, "--config", str(station))
    assert status == 2, (printed, error)
    assert error == f"boltwatch {label}: {folder}: {LOOP}\n"


@pytest.mark.parametrize("command", ["results", "results rebuild"])
def test_recordings_option_naming_a_link_to_itself_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    folder = tmp_path / "recordings"
    folder.symlink_to(folder.name)
    status, _, error = _run(capsys, *command.split(), "--recordings", str(folder))
    assert status == 2
    assert error == f"boltwatch results: --recordings: {folder}: {LOOP}\n"


def _named_once(error: str, loop: Path) -> bool:
    return sum(f"{loop}: {LOOP}" in line for line in error.splitlines()) == 1


def test_report_from_the_recordings_skips_each_loop_and_names_it(
    holding: tuple[Path, Path, list[Path]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    station, _, (_, day_loop, file_loop) = holding
    arguments = ["--from-recordings", "--out", str(tmp_path / "out")]
    status, printed, error = _run(capsys, "report", "--config", str(station), *arguments)
    assert status == 0, error
    assert "program 1 (M14 to 56 kN): 1 runs" in printed
    assert _named_once(error, day_loop) and _named_once(error, file_loop)
    assert "files not readable, skipped: 2" in printed


@pytest.mark.parametrize("source", ["--config", "--recordings"])
def test_rebuild_skips_each_loop_and_names_it(
    holding: tuple[Path, Path, list[Path]], capsys: pytest.CaptureFixture[str], source: str
) -> None:
    station, folder, (station_loop, day_loop, file_loop) = holding
    given = str(station) if source == "--config" else str(folder)
    status, printed, error = _run(capsys, "results", "rebuild", source, given)
    assert status == 0, error
    assert "1 results, 1 new" in printed
    assert _named_once(error, day_loop) and _named_once(error, file_loop)
    # every station folder of --recordings is read: st2's is a loop
    assert _named_once(error, station_loop) == (source == "--recordings")
    with ResultsStore(store_target(folder, None), create=False) as store:
        assert store.count(ResultsQuery()) == 1


def test_overlay_skips_a_loop_among_the_day_folders_and_names_it(
    holding: tuple[Path, Path, list[Path]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    station, _, (_, day_loop, _) = holding
    target = tmp_path / "overlay.png"
    arguments = ["--overlay", "5", "--config", str(station), "--out", str(target)]
    status, printed, error = _run(capsys, "inspect", *arguments)
    assert status == 0, error
    assert _named_once(error, day_loop) and "wrote" in printed
    assert target.read_bytes().startswith(b"\x89PNG")


def test_prune_skips_each_loop_and_names_it(
    holding: tuple[Path, Path, list[Path]], capsys: pytest.CaptureFixture[str]
) -> None:
    station, folder, (_, day_loop, file_loop) = holding
    assert main(["results", "rebuild", "--config", str(station)]) == 0
    capsys.readouterr()
    status, printed, error = _run(capsys, "recordings", "prune", "--config", str(station))
    assert status == 0, error
    assert _named_once(error, day_loop) and _named_once(error, file_loop)
    assert printed.startswith(f"recordings of {folder} (st1)")
    assert all(loop.is_symlink() for loop in (day_loop, file_loop))  # never touched


def test_the_recorder_refuses_a_folder_that_is_a_link_to_itself_at_start(
    looping: tuple[Path, Path],
) -> None:
    station, folder = looping
    with pytest.raises(ConfigError, match=f"recorder.folder: {folder}: {LOOP}"):
        load_station(station).make_recordings_folder()


def test_the_recorders_catch_up_skips_each_loop_and_names_it(
    holding: tuple[Path, Path, list[Path]], caplog: pytest.LogCaptureFixture
) -> None:
    """The catch-up at start reads the recordings of today and yesterday (none stored: it
    reads from two minutes before the start): it names the loop among the day folders and
    the one among today's files, and stores today's run."""
    from services.recorder.results_watch import ResultsWatch

    _, folder, (_, day_loop, _) = holding
    now_ns = time.time_ns()
    today = write_run_file(folder, 6, now_ns, [factories.result(6, time_ns=now_ns)])
    file_loop = today.with_name("st1_run98_000000.mcap")
    file_loop.symlink_to(file_loop.name)
    caplog.set_level(logging.WARNING)
    watch = ResultsWatch(store_target(folder, None), folder, {"st1": StationPlace()}, "box")
    try:
        wait_until(lambda: watch.stored == 1, "the catch-up", 30.0)
    finally:
        watch.close()
    lines = [record.getMessage() for record in caplog.records if LOOP in record.getMessage()]
    assert len(lines) == 2, lines
    assert _named_once("\n".join(lines), day_loop) and _named_once("\n".join(lines), file_loop)
