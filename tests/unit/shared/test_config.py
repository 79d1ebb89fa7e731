"""Station and joint files: the shipped ones load; bad ones fail with file, key, expectation."""

from __future__ import annotations

from pathlib import Path

import pytest

from shared.config import load_joint, load_station
from shared.errors import ConfigError
from tests.paths import CONFIG, STATION_FILE

STATION_TEXT = STATION_FILE.read_text()


def write_station(tmp_path: Path, text: str) -> Path:
    """A copy of the shipped station file with absolute paths, edited by ``text`` replacements."""
    body = STATION_TEXT.replace('"joints/', f'"{CONFIG}/joints/').replace(
        '"can/', f'"{CONFIG}/can/'
    )
    path = tmp_path / "station.toml"
    path.write_text(body + text)
    return path


def test_shipped_files_load() -> None:
    station = load_station(STATION_FILE)
    assert station.station_id == "st1"
    assert station.config.program(1).target_force_n == 56000.0
    assert station.dbc_path.is_file() and station.joint_path.is_file()
    assert station.joint.friction.mu_stick == 0.38
    for joint_file in (CONFIG / "joints").glob("*.toml"):
        load_joint(joint_file)


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        ('channel = "239', 'chanel = "239', "can.chanel: unknown key; expected one of: channel"),
        ("target_force_n = 56000.0", "target_force_n = -5.0", "programs[0].target_force_n:"),
        ('interface = "udp_multicast"', 'interface = "canbus"', "can.interface: Input should be"),
        ("tool_id = 7", 'tool_id = "seven"', "station.tool_id:"),
        ('id = "st1"', 'id = "st 1/x"', "station.id: String should match pattern"),
        ("[predictor]\nwindow_samples = 5", "[predictor]\nwindow_samples = 1", "window_samples"),
    ],
)
def test_bad_value_names_file_and_key(tmp_path: Path, old: str, new: str, expected: str) -> None:
    path = write_station(tmp_path, "")
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))
    with pytest.raises(ConfigError) as caught:
        load_station(path)
    message = str(caught.value)
    assert message.startswith(f"{path}: ")
    assert expected in message


def test_program_without_target_and_duplicate_ids_are_errors(tmp_path: Path) -> None:
    path = write_station(tmp_path, "")
    text = path.read_text().replace("target_force_n = 40000.0\n", "")
    path.write_text(text)
    with pytest.raises(ConfigError, match=r"programs\[1\]: give target_force_n"):
        load_station(path)
    path.write_text(write_station(tmp_path, "").read_text().replace("id = 2", "id = 1"))
    with pytest.raises(ConfigError, match="program ids must be unique"):
        load_station(path)


def test_missing_files_and_bad_toml_name_the_file(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="file not found"):
        load_station(tmp_path / "nope.toml")
    broken = tmp_path / "broken.toml"
    broken.write_text("[station\nid = 1")
    with pytest.raises(ConfigError, match=r"broken\.toml: not valid TOML"):
        load_station(broken)
    path = write_station(tmp_path, "")
    path.write_text(path.read_text().replace("paper-section-5-2.toml", "missing.toml"))
    with pytest.raises(ConfigError, match=r"station\.joint: file not found"):
        load_station(path)


def test_joint_file_checks_physics(tmp_path: Path) -> None:
    text = (CONFIG / "joints" / "paper-section-5-2.toml").read_text()
    path = tmp_path / "joint.toml"
    path.write_text(text.replace("mu_slip = 0.35", "mu_slip = 0.45"))
    with pytest.raises(ConfigError, match="friction: mu_slip must not exceed mu_stick"):
        load_joint(path)
