"""``recorder.wear_forecast_days``: the horizons a tool's service forecast is said within."""

from __future__ import annotations

from pathlib import Path

import pytest

from shared.config import load_station
from shared.errors import ConfigError
from tests.support.config_files import write_station


def with_recorder_keys(tmp_path: Path, text: str) -> Path:
    path = write_station(tmp_path, "")
    body = path.read_text().replace("[recorder]\n", f"[recorder]\n{text}\n", 1)
    path.write_text(body)
    return path


def test_a_week_by_default_and_any_few_horizons_or_none(tmp_path: Path) -> None:
    assert load_station(write_station(tmp_path, "")).config.recorder.wear_forecast_days == [7.0]
    path = with_recorder_keys(tmp_path, "wear_forecast_days = [14, 3.5, 1]")
    assert load_station(path).config.recorder.wear_forecast_days == [14.0, 3.5, 1.0]
    path = with_recorder_keys(tmp_path, "wear_forecast_days = []")
    assert load_station(path).config.recorder.wear_forecast_days == []


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        ("[0]", "recorder.wear_forecast_days[0]: Input should be greater than 0"),
        ("[7, 400]", "recorder.wear_forecast_days[1]: Input should be less than or equal to 365"),
        ("[1, 2, 3, 4, 5, 6]", "recorder.wear_forecast_days: List should have at most 5 items"),
        ("7", "recorder.wear_forecast_days: Input should be a valid list"),
    ],
)
def test_bad_horizons_name_the_file_and_the_key(tmp_path: Path, value: str, expected: str) -> None:
    path = with_recorder_keys(tmp_path, f"wear_forecast_days = {value}")
    with pytest.raises(ConfigError) as refused:
        load_station(path)
    assert str(path) in str(refused.value)
    assert expected in str(refused.value)
