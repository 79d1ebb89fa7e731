"""The station file's ``[retention]`` section: none deletes nothing, bad keys are refused naming
file, key and what was expected, and one recorder's files must agree on it."""

from __future__ import annotations

from pathlib import Path

import pytest

from services.cli.main import main
from services.recorder.served_stations import served_stations
from shared.config import load_any_station, load_station
from shared.errors import ConfigError
from tests.support.config_files import write_station
from tests.support.paths import CONFIG


def test_without_the_section_nothing_is_ever_deleted(tmp_path: Path) -> None:
    retention = load_station(write_station(tmp_path, "")).config.retention
    assert (retention.keep_days, retention.keep_nok_days, retention.max_disk_used_pct) == (
        None,
        None,
        None,
    )
    assert not retention.deletes
    assert retention.describe() == "every curve kept for ever"


def test_a_section_sets_every_key(tmp_path: Path) -> None:
    text = "\n[retention]\nkeep_days = 30\nkeep_nok_days = 365\nmax_disk_used_pct = 90\n"
    retention = load_station(write_station(tmp_path, text)).config.retention
    assert retention.deletes
    assert (retention.keep_days, retention.keep_nok_days, retention.max_disk_used_pct) == (
        30,
        365,
        90.0,
    )
    assert retention.keep_ns == 30 * 86_400 * 10**9
    assert retention.keep_nok_ns == 365 * 86_400 * 10**9
    assert retention.describe() == ("curves kept 30 days, NOK 365 days, the disk at most 90 % used")


def test_nok_runs_follow_keep_days_unless_told(tmp_path: Path) -> None:
    retention = load_station(write_station(tmp_path, "\n[retention]\nkeep_days = 7\n")).config
    assert retention.retention.keep_nok_ns == retention.retention.keep_ns == 7 * 86_400 * 10**9


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("keep_days = 0", "retention.keep_days: Input should be greater than or equal to 1"),
        ("keep_days = 1.5", "retention.keep_days: Input should be a valid integer"),
        ('keep_days = "30d"', "retention.keep_days: Input should be a valid integer"),
        (
            "max_disk_used_pct = 100",
            "retention.max_disk_used_pct: Input should be less than or equal to 99 (got 100)",
        ),
        (
            "max_disk_used_pct = 0.5",
            "retention.max_disk_used_pct: Input should be greater than or equal to 1",
        ),
        (
            "keep_nok_days = 90",
            "retention: keep_nok_days needs keep_days (without it every recording is kept",
        ),
        (
            "keep_days = 30\nkeep_nok_days = 7",
            "retention: keep_nok_days (7) must not be less than keep_days (30)",
        ),
        (
            "keep_day = 30",
            "retention.keep_day: unknown key; expected one of: keep_days, keep_nok_days, "
            "max_disk_used_pct",
        ),
    ],
)
def test_bad_keys_name_the_file_the_key_and_what_was_expected(
    tmp_path: Path, text: str, expected: str
) -> None:
    path = write_station(tmp_path, f"\n[retention]\n{text}\n")
    with pytest.raises(ConfigError) as refused:
        load_station(path)
    message = str(refused.value)
    assert message.startswith(f"{path}: ") and expected in message
    assert "\n" not in message


def test_a_controller_station_takes_the_section(tmp_path: Path) -> None:
    text = (CONFIG / "controller-station.toml").read_text()
    path = tmp_path / "op1.toml"
    path.write_text(text + "\n[retention]\nkeep_days = 90\n")
    assert load_any_station(path).config.retention.keep_days == 90


def test_one_recorders_files_must_agree_on_it(tmp_path: Path) -> None:
    """Two stations of one recorder, one folder (``../recordings`` of each): one section."""
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    a = write_station(tmp_path / "a", "\n[retention]\nkeep_days = 30\n")
    b = write_station(tmp_path / "b", "\n[retention]\nkeep_days = 60\n")
    b.write_text(b.read_text().replace('id = "st1"', 'id = "st2"', 1))
    with pytest.raises(ConfigError) as refused:
        served_stations([load_station(a), load_station(b)])
    message = str(refused.value)
    assert message.startswith(f"{b}: retention.keep_days: 60 differs from 30 of {a}")
    assert "one [retention] section" in message


def test_the_recorder_refuses_a_bad_section_with_one_line_and_status_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = write_station(tmp_path, "\n[retention]\nkeep_days = 30\nkeep_nok_days = 7\n")
    assert main(["serve", "recorder", "--config", str(path)]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "keep_nok_days (7) must not be less than" in error
    assert "Traceback" not in error
