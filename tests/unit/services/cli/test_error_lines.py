"""What a plant engineer reads when a path or a value is wrong: one line naming the file (or
the option), what is wrong and why, exit status 2.

The no-traceback tests (``test_no_traceback.py``) drive every command with every kind of
bad value; these pin the words for the cases a person meets most and for each mechanism:
OSErrors told by ``services/cli/error_lines.py``, numbers refused while parsing
(``shared/option_types.py``), endpoints, station files that are not text.
"""

from __future__ import annotations

import os
import re
import stat
from collections.abc import Iterator

import pytest

from services.cli.main import main
from tests.support.bad_arguments import LOG_LINE, Workspace


def fails_with(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """Run ``boltwatch ARGV`` in-process; it must exit 2 with one line on stderr: that line."""
    try:
        status = main(argv)
    except SystemExit as exit_:  # argparse refused a value
        status = int(exit_.code or 0)
    err = capsys.readouterr().err
    lines = [
        line
        for line in err.splitlines()
        if line.strip() and not line.startswith((" ", "usage:")) and not LOG_LINE.match(line)
    ]
    assert status == 2, err
    assert len(lines) == 1, err
    return lines[0]


@pytest.fixture
def workspace() -> Iterator[Workspace]:
    with Workspace() as space:
        yield space


# -- paths: the OSError of any command, told in one line -----------------------------------


@pytest.mark.parametrize(
    ("argv", "line"),
    [
        (
            ["export", "good.mcap", "--out", "no-folder/run.csv"],
            "boltwatch export: no-folder/run.csv: folder no-folder does not exist",
        ),
        (
            ["export", "good.mcap", "--out", "a-file.txt/run.csv"],
            "boltwatch export: a-file.txt/run.csv: a-file.txt is a file, not a folder",
        ),
        (
            ["export", "good.mcap", "--out", "a-folder"],
            "boltwatch export: a-folder: is a folder, not a file",
        ),
        (
            ["inspect", "good.mcap", "--out", "no-folder/run.png"],
            "boltwatch inspect: no-folder/run.png: folder no-folder does not exist",
        ),
        (
            ["model", "--joint", "joint.toml", "--plot", "a-file.txt/x/joint.png"],
            "boltwatch model: a-file.txt/x/joint.png: a-file.txt is a file, not a folder",
        ),
        (
            ["recover", "good.mcap", "--out", "a-folder"],
            "boltwatch recover: a-folder: is a folder, not a file",
        ),
        (
            ["simulate", "--config", "station.toml", "--out", "no-folder/run.csv"],
            "boltwatch simulate: no-folder/run.csv: folder no-folder does not exist",
        ),
        (
            ["wear", "service", "7", "--recordings", "a-file.txt"],
            "boltwatch wear: a-file.txt: already exists and is not a folder",
        ),
    ],
    ids=lambda value: value[0] if isinstance(value, list) else "",
)
def test_a_bad_path_is_one_line_naming_it(
    argv: list[str], line: str, workspace: Workspace, capsys: pytest.CaptureFixture[str]
) -> None:
    assert fails_with(argv, capsys) == line


def test_a_picture_that_is_not_a_png_is_refused_before_drawing(
    workspace: Workspace, capsys: pytest.CaptureFixture[str]
) -> None:
    """matplotlib would have written ``run.png`` beside a ``--out run`` (and into /dev for
    ``--out /dev/full``) and said it wrote ``run``."""
    line = fails_with(["inspect", "good.mcap", "--out", "run"], capsys)
    assert (
        line == "boltwatch inspect: run: the report is written as PNG; give a path ending in .png"
    )
    assert sorted(p.name for p in workspace.path.glob("run*")) == []


def test_a_recovery_into_a_device_leaves_the_device(
    workspace: Workspace, capsys: pytest.CaptureFixture[str]
) -> None:
    """``recover --out /dev/full`` removed /dev/full when the copy failed (run as root); the
    workspace's own ``full`` (a /dev/full made with mknod) stands in for it."""
    device = workspace.path / "full"
    if not device.exists():
        pytest.skip("no permission to make a device file here (needs CAP_MKNOD)")
    line = fails_with(["recover", "good.mcap", "--out", "full"], capsys)
    assert line == "boltwatch recover: full: no space left on device"
    assert stat.S_ISCHR(os.stat(device).st_mode)
    line = fails_with(["export", "good.mcap", "--out", "full"], capsys)
    assert line == "boltwatch export: full: no space left on device"


def test_recover_names_a_missing_source_and_writes_nothing(
    workspace: Workspace, capsys: pytest.CaptureFixture[str]
) -> None:
    """The target used to be opened first: a missing source was reported as its target."""
    line = fails_with(["recover", "no-folder/run.mcap"], capsys)
    assert line == "boltwatch recover: no-folder/run.mcap: file not found"
    assert not (workspace.path / "no-folder").exists()


# -- numbers and words refused while the command line is parsed ----------------------------


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["serve", "acquisition", "--stats-interval-s", "nan"], "--stats-interval-s: expected a"),
        (["serve", "acquisition", "--stats-interval-s", "0"], "--stats-interval-s: expected a"),
        (["serve", "recorder", "--rerun-port", "0"], "--rerun-port: expected a port number"),
        (["serve", "rig", "--log-level", "loud"], "--log-level: invalid choice: 'LOUD'"),
        (["status", "--listen-s", "inf"], "--listen-s: expected a number above 0 up to"),
        (["up", "--startup-timeout-s", "-1"], "--startup-timeout-s: expected a number above"),
        (["model", "--speed", "1e308"], "--speed: expected a number from 0.001 up to 1000 rad/s"),
        (["model", "--target-torque", "inf"], "--target-torque: expected a number above 0"),
        (["wear", "service", "99999999999999999999"], "tool: expected a tool id from 0 to 65535"),
    ],
    ids=lambda value: " ".join(value[:2]) if isinstance(value, list) else "",
)
def test_an_impossible_number_is_refused_before_anything_runs(
    argv: list[str], expected: str, workspace: Workspace, capsys: pytest.CaptureFixture[str]
) -> None:
    line = fails_with(argv, capsys)
    assert line.startswith(f"boltwatch {' '.join(argv[: 2 if argv[0] == 'serve' else 1])}")
    assert expected in line


def test_up_refuses_an_unknown_program_and_numbers_past_its_ranges(
    workspace: Workspace, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--program 99`` was a KeyError; ``--stations 10**17`` built ids for ever and
    ``--runs 10**17`` started the whole station before the rig refused it."""
    line = fails_with(["up", "--config", "station.toml", "--program", "99"], capsys)
    assert line == "boltwatch up: station.toml: no program 99 (--program; the file has 1, 2, 3)"
    line = fails_with(["up", "--config", "station.toml", "--stations", str(10**17)], capsys)
    assert re.fullmatch(
        r"boltwatch up: station.toml: can.port: \d+ \+ \d+ stations exceeds 65535", line
    )
    line = fails_with(["up", "--config", "station.toml", "--runs", str(10**17)], capsys)
    assert line.startswith("boltwatch up: --runs must be at most ")


# -- endpoints and zenoh's own words --------------------------------------------------------


def test_an_endpoint_zenoh_cannot_parse_is_named(
    workspace: Workspace, capsys: pytest.CaptureFixture[str]
) -> None:
    expected = "expected <protocol>/<address>:<port>, e.g. tcp/127.0.0.1:7447"
    line = fails_with(["status", "--connect", "notanendpoint"], capsys)
    assert line == f"boltwatch status: zenoh endpoint 'notanendpoint': {expected}"
    line = fails_with(["serve", "router", "--listen", "tcp/"], capsys)
    assert line == f"boltwatch serve router: zenoh endpoint 'tcp/': {expected}"
    station = workspace.path / "station.toml"
    station.write_text(
        re.sub(r'connect = \["[^"]*"\]', 'connect = ["router"]', station.read_text())
    )
    line = fails_with(["health", "rig", "--config", "station.toml"], capsys)
    assert line == (
        f"boltwatch health: station.toml: zenoh.connect[0]: not a zenoh endpoint: {expected}"
        " (got 'router')"
    )


def test_zenoh_errors_lose_their_rust_source_locations(
    workspace: Workspace, capsys: pytest.CaptureFixture[str]
) -> None:
    line_placed = workspace.path / "line-station.toml"  # a line predictor's station
    text = (workspace.path / "station.toml").read_text()
    line_placed.write_text(text.replace("[predictor]\n", '[predictor]\nplacement = "line"\n'))
    line = fails_with(["serve", "predictor", "--config", "line-station.toml"], capsys)
    assert "no zenoh router at tcp/127.0.0.1:" in line and line.endswith("Timeout!")
    line = fails_with(["serve", "router", "--access-control", "empty.toml"], capsys)
    assert line.endswith(
        "policies): line 1, column 1: expected array, boolean, null, number, object, or string"
    )


# -- files that are not what they should be --------------------------------------------------


def test_a_station_file_that_is_not_text_or_is_empty_is_one_line(
    workspace: Workspace, capsys: pytest.CaptureFixture[str]
) -> None:
    line = fails_with(["simulate", "--config", "binary.bin", "--out", "run.csv"], capsys)
    assert re.fullmatch(r"boltwatch simulate: binary.bin: not a text file \(byte \d+: .+\)", line)
    line = fails_with(["serve", "router", "--access-control", "binary.bin"], capsys)
    assert line.startswith("boltwatch serve router: --access-control binary.bin: not a text file")
    line = fails_with(["status", "--config", "empty.toml"], capsys)
    assert line == (
        "boltwatch status: empty.toml: station, can, zenoh, programs, recorder: Field required"
    )
    line = fails_with(["model", "--joint", "station.toml"], capsys)
    assert line.startswith(
        "boltwatch model: station.toml: name, material, screw, extension, friction: "
        "Field required; station, can, zenoh, programs, predictor, rig, recorder: unknown keys"
    )
