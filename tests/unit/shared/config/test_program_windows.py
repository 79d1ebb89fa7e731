"""A program's windows in the station file; a window that cannot work is refused."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from shared.config import load_station
from shared.errors import ConfigError
from tests.support.paths import CONFIG, STATION_FILE

PROGRAM_1 = "max_time_s = 6.0\n"
SHIPPED_WINDOW = r"^(torque|angle|force)_(min|max)_(nm|deg|n) = .*\n"


def station_with(tmp_path: Path, program_1_keys: str, old: str = "", new: str = "") -> Path:
    """The shipped station file, absolute paths, its windows replaced by ``program_1_keys``."""
    text = re.sub(SHIPPED_WINDOW, "", STATION_FILE.read_text(), flags=re.MULTILINE)
    text = text.replace('"joints/', f'"{CONFIG}/joints/').replace('"can/', f'"{CONFIG}/can/')
    assert PROGRAM_1 in text
    text = text.replace(PROGRAM_1, PROGRAM_1 + program_1_keys, 1)
    if old:
        assert old in text
        text = text.replace(old, new, 1)
    path = tmp_path / "station.toml"
    path.write_text(text)
    return path


def test_the_shipped_station_judges_program_1_and_not_program_2() -> None:
    config = load_station(STATION_FILE).config
    assert config.program(1).window("force") == (53000.0, 59000.0)
    assert config.program(1).window("torque") == (180.0, 240.0)
    assert config.program(1).window("angle") == (35.0, 65.0)
    assert config.program(2).window("force") == (None, None)


def test_windows_are_read_each_bound_optional(tmp_path: Path) -> None:
    keys = "torque_min_nm = 150.0\nforce_min_n = 53000\nforce_max_n = 59e3\n"
    path = station_with(tmp_path, keys)
    program = load_station(path).config.program(1)
    assert program.window("torque") == (150.0, None)
    assert program.window("angle") == (None, None)
    assert program.window("force") == (53000.0, 59000.0)
    assert load_station(path).config.program(2).window("torque") == (None, None)


@pytest.mark.parametrize(
    ("keys", "expected"),
    [
        (
            "torque_min_nm = 250.0\ntorque_max_nm = 200.0\n",
            "programs[0]: torque_min_nm 250 Nm is not below torque_max_nm 200 Nm: "
            "no run could be OK",
        ),
        (
            "angle_min_deg = 30.0\nangle_max_deg = 30.0\n",
            "programs[0]: angle_min_deg 30 deg is not below angle_max_deg 30 deg",
        ),
        (
            "force_min_n = 80000.0\n",
            "programs[0]: force_min_n 80000 N is not below the hard limit max_force_n 75000 N",
        ),
        (
            "torque_min_nm = 400.0\n",
            "programs[0]: torque_min_nm 400 Nm is not below the hard limit max_torque_nm 320 Nm",
        ),
        ("torque_max_nm = 9000.0\n", "programs[0].torque_max_nm: 9000 Nm is beyond what the"),
        ("angle_min_deg = -1e6\n", "programs[0].angle_min_deg: -1e+06 deg is beyond what the"),
        ('torque_max_nm = "high"\n', "programs[0].torque_max_nm: Input should be a valid number"),
        ("torque_window_nm = 5.0\n", "programs[0].torque_window_nm: unknown key"),
        ("force_max_n = nan\n", "programs[0].force_max_n: "),
    ],
)
def test_a_window_that_cannot_work_is_refused_naming_file_and_key(
    tmp_path: Path, keys: str, expected: str
) -> None:
    path = station_with(tmp_path, keys)
    with pytest.raises(ConfigError, match="^" + re.escape(f"{path}: {expected}")):
        load_station(path)


def test_a_preload_window_without_a_force_sensor_is_refused(tmp_path: Path) -> None:
    path = station_with(
        tmp_path, "force_max_n = 60000.0\n", "has_force_sensor = true", "has_force_sensor = false"
    )
    with pytest.raises(ConfigError) as caught:
        load_station(path)
    assert str(caught.value).startswith(
        f"{path}: programs[0]: force_min_n / force_max_n need a force sensor"
    )
