"""Station and joint files: the shipped ones load; bad ones fail with file, key, expectation."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from shared.config import StationPlace, load_joint, load_station
from shared.contract import StationDatabase
from shared.errors import CanDatabaseError, ConfigError
from tests.support.config_files import write_station
from tests.support.paths import CONFIG, STATION_FILE


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
        ("tool_id = 7", 'tool_id = 7\nplant = "North\\u0007"', "station.plant: String should"),
        ("tool_id = 7", f'tool_id = 7\nname = "{"x" * 65}"', "station.name: String should"),
        ("tool_id = 7", 'tool_id = 7\nplnat = "North"', "station.plnat: unknown key"),
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


def test_the_station_says_where_it_is_in_the_plant(tmp_path: Path) -> None:
    assert load_station(STATION_FILE).config.station.place == StationPlace("", "", "")
    path = write_station(tmp_path, "")
    path.write_text(
        path.read_text().replace(
            "tool_id = 7", 'tool_id = 7\nplant = "North"\nline = "B"\nname = "Wheel nuts, left"'
        )
    )
    assert load_station(path).config.station.place == StationPlace("North", "B", "Wheel nuts, left")


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


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        (
            "max_force_n = 75000.0",
            "max_force_n = 50000.0",
            "programs[0]: max_force_n 50000 N is not above target_force_n 56000 N",
        ),
        (
            "max_torque_nm = 320.0",
            "max_torque_nm = 200.0",
            "programs[0]: max_torque_nm 200 Nm is not above target_torque_nm 200 Nm",
        ),
        (
            "start_force_n = 10000.0",
            "start_force_n = 60000.0",
            "programs[0]: start_force_n 60000 N is not below target_force_n 56000 N",
        ),
    ],
)
def test_a_program_that_cannot_work_is_refused_at_start(
    tmp_path: Path, old: str, new: str, expected: str
) -> None:
    """Max_force_n below the target was accepted and every run ended on force_limit."""
    path = write_station(tmp_path, "")
    path.write_text(path.read_text().replace(old, new, 1))
    with pytest.raises(ConfigError, match=r"^" + re.escape(f"{path}: {expected}")):
        load_station(path)


def test_a_dbc_scaling_that_cannot_carry_the_limits_is_refused_at_start(tmp_path: Path) -> None:
    """A DBC scaling too narrow for the torque crashed the rig (OverflowError)."""
    narrow = tmp_path / "narrow.dbc"
    narrow.write_text(
        (CONFIG / "can" / "station.dbc")
        .read_text()
        .replace(
            'SG_ Torque : 0|24@1- (0.001,0) [-8388.608|8388.607] "Nm"',
            'SG_ Torque : 0|16@1- (0.001,0) [-32.768|32.767] "Nm"',
        )
    )
    path = write_station(tmp_path, "")
    path.write_text(path.read_text().replace(f'"{CONFIG}/can/station.dbc"', f'"{narrow}"'))
    with pytest.raises(ConfigError) as caught:
        load_station(path)
    assert str(caught.value).startswith(
        f"{path}: programs[0].max_torque_nm: 320 Nm is beyond what the sensor can report "
        f"(-32.768 to 32.767 Nm) in the scaling of {narrow}"
    )


def test_a_recordings_folder_that_cannot_be_made_is_refused_naming_the_key(
    tmp_path: Path,
) -> None:
    """``[recorder] folder`` under a file was a NotADirectoryError traceback."""
    (tmp_path / "afile").write_text("not a folder")
    path = write_station(tmp_path, "")
    text = path.read_text()
    path.write_text(text.replace('folder = "../recordings"', 'folder = "afile/recordings"'))
    station = load_station(path)
    with pytest.raises(ConfigError) as caught:
        station.make_recordings_folder()
    assert str(caught.value) == (
        f"{path}: recorder.folder: {tmp_path}/afile/recordings: cannot be made: "
        f"{tmp_path}/afile is a file, not a folder"
    )


def test_a_program_may_tighten_a_joint_of_its_own(tmp_path: Path) -> None:
    """One station, several bolts: each program's joint feeds its predictor and its rig."""
    path = write_station(tmp_path, "")
    text = path.read_text().replace(
        "max_time_s = 4.0", f'max_time_s = 4.0\njoint = "{CONFIG}/joints/paper-section-3-4.toml"'
    )
    path.write_text(text)
    station = load_station(path)
    assert station.joint_of(1) is station.joint  # program 1 names none: the station's
    assert station.joint_of(2) == load_joint(CONFIG / "joints" / "paper-section-3-4.toml")
    assert station.joint_of(2) != station.joint
    path.write_text(text.replace("paper-section-3-4.toml", "missing.toml"))
    with pytest.raises(ConfigError, match=r"programs\[1\]\.joint: file not found"):
        load_station(path)


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        (
            "speed_rad_s = 0.05",
            "speed_rad_s = 0.5",
            "programs[2]: final_stage.speed_rad_s 0.5 rad/s is not below motor_speed_rad_s "
            "0.5 rad/s",
        ),
        (
            'switch = "predicted"',
            'switch = "torque"',
            "programs[2].final_stage: switch = 'torque' needs switch_torque_nm",
        ),
        (
            'switch = "predicted"',
            'switch = "torque"\nswitch_torque_nm = 200.0',
            "programs[2]: final_stage.switch_torque_nm 200 Nm is not below target_torque_nm",
        ),
        (
            'switch = "predicted"',
            'switch = "predicted"\nswitch_torque_nm = 150.0',
            "programs[2].final_stage: switch_torque_nm applies only to switch = 'torque'",
        ),
        ("max_pulses = 2", "max_pulses = 16", "programs[2].final_stage.max_pulses: "),
        ("max_pulses = 2", "max_pulse = 2", "programs[2].final_stage.max_pulse: unknown key"),
    ],
)
def test_a_final_stage_that_cannot_work_is_refused_naming_its_key(
    tmp_path: Path, old: str, new: str, expected: str
) -> None:
    path = write_station(tmp_path, "")
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))
    with pytest.raises(ConfigError, match=r"^" + re.escape(f"{path}: {expected}")):
        load_station(path)


def test_a_dbc_with_one_of_the_final_stage_messages_is_refused(tmp_path: Path) -> None:
    text = (CONFIG / "can" / "station.dbc").read_text()
    half = tmp_path / "half.dbc"
    half.write_text(text.replace("BO_ 129 ToolStage", "BO_ 129 ToolStagez"))
    with pytest.raises(CanDatabaseError, match="has StageCommand but not ToolStage"):
        StationDatabase(half)
    assert StationDatabase(CONFIG / "can" / "station.dbc").has_stages
