"""The options export, inspect, wear and import share (services/cli/command_options.py)."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

from services.cli.command_options import (
    DEFAULT_STATION_FILE,
    add_recording_argument,
    add_recordings_folder_options,
    add_run_option,
    recordings_folder,
    warn_damaged_recording,
)
from shared.errors import BoltwatchError
from tests.support.station_files import write_station


def _folder_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="t")
    add_recordings_folder_options(parser)
    return parser


def test_recordings_option_wins_and_the_station_file_is_not_read(tmp_path: Path) -> None:
    args = _folder_parser().parse_args(
        ["--recordings", str(tmp_path / "here"), "--config", str(tmp_path / "missing.toml")]
    )
    assert recordings_folder(args) == tmp_path / "here"


def test_without_recordings_the_station_files_folder_is_used(tmp_path: Path) -> None:
    station = write_station(tmp_path)
    args = _folder_parser().parse_args(["--config", str(station)])
    assert recordings_folder(args) == tmp_path / "recordings"


def test_a_missing_station_file_is_one_clear_error(tmp_path: Path) -> None:
    args = _folder_parser().parse_args(["--config", str(tmp_path / "missing.toml")])
    with pytest.raises(BoltwatchError, match=r"missing\.toml"):
        recordings_folder(args)


def test_defaults_when_nothing_is_given() -> None:
    parser = argparse.ArgumentParser(prog="t")
    add_recording_argument(parser)
    add_run_option(parser, "run id")
    add_recordings_folder_options(parser)
    args = parser.parse_args(["run.mcap"])
    assert args.recording == Path("run.mcap")
    assert args.run is None
    assert args.recordings is None
    assert args.config == DEFAULT_STATION_FILE == Path("config/station.toml")
    assert parser.parse_args(["run.mcap", "--run", "7"]).run == 7


def test_damage_warning_is_one_line_on_stderr(capsys: pytest.CaptureFixture[str]) -> None:
    warn_damaged_recording("export", "truncated after 3 chunks", "exported what is readable")
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == (
        "boltwatch export: warning: truncated after 3 chunks; exported what is readable\n"
    )


def test_a_result_id_option_takes_every_id_the_contract_allows() -> None:
    from services.cli.command_options import RESULT_ID_MAX
    from shared.contract import INT64_MAX

    assert RESULT_ID_MAX == INT64_MAX
