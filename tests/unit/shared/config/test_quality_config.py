"""The station file's ``[quality]`` section: defaults, and bad keys refused naming file and key."""

from __future__ import annotations

from pathlib import Path

import pytest

from services.cli.main import main
from shared.config import load_station
from shared.errors import ConfigError
from tests.support.config_files import write_station


def test_defaults_when_the_section_is_absent(tmp_path: Path) -> None:
    quality = load_station(write_station(tmp_path, "")).config.quality
    assert (quality.cpk_min, quality.window_runs, quality.min_runs) == (1.33, 50, 20)
    assert (quality.nok_run, quality.nok_window, quality.nok_max) == (3, 20, 5)


def test_a_section_sets_every_key(tmp_path: Path) -> None:
    text = (
        "\n[quality]\ncpk_min = 1.67\nwindow_runs = 30\nmin_runs = 10\n"
        "nok_run = 2\nnok_window = 10\nnok_max = 4\n"
    )
    quality = load_station(write_station(tmp_path, text)).config.quality
    assert (quality.cpk_min, quality.window_runs, quality.min_runs) == (1.67, 30, 10)
    assert (quality.nok_run, quality.nok_window, quality.nok_max) == (2, 10, 4)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("cpk_min = 0", "quality.cpk_min: Input should be greater than 0 (got 0)"),
        ('cpk_min = "high"', "quality.cpk_min: Input should be a valid number"),
        ("nok_run = 0", "quality.nok_run: Input should be greater than or equal to 1"),
        ("window_runs = 1", "quality.window_runs: Input should be greater than or equal to 2"),
        ("min_runs = 60", "quality: min_runs (60) must not exceed window_runs (50)"),
        ("nok_max = 8\nnok_window = 5", "quality: nok_max (8) must not exceed nok_window (5)"),
        ("cpk_minimum = 1.0", "quality.cpk_minimum: unknown key; expected one of: cpk_min"),
    ],
)
def test_bad_keys_name_the_file_and_the_key(tmp_path: Path, text: str, expected: str) -> None:
    path = write_station(tmp_path, f"\n[quality]\n{text}\n")
    with pytest.raises(ConfigError) as refused:
        load_station(path)
    message = str(refused.value)
    assert message.startswith(f"{path}: ") and expected in message
    assert "\n" not in message


def test_the_recorder_refuses_a_bad_section_with_one_line_and_status_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = write_station(tmp_path, "\n[quality]\nnok_max = 30\n")
    assert main(["serve", "recorder", "--config", str(path)]) == 2
    error = capsys.readouterr().err
    assert (
        error.count("\n") == 1 and "quality: nok_max (30) must not exceed nok_window (20)" in error
    )
    assert "Traceback" not in error
