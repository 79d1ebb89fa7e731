"""A controller station's file: ``[openprotocol]`` without ``[can]``, no joint, no motor.

The shipped example loads; a pset carries only id, name and torque/angle windows; every
key of a CAN station refused by name (file, key, why); CAN stations stay as strict as
before (tests/unit/shared/config/test_config.py) and refuse to be read as a controller's.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from shared.config import (
    ControllerStation,
    LoadedStation,
    load_any_line,
    load_any_station,
    load_station,
)
from shared.contract import CONTRACT_RANGE
from shared.errors import ConfigError
from tests.support.paths import CONFIG, STATION_FILE

CONTROLLER_FILE = CONFIG / "controller-station.toml"

MINIMAL = """\
[station]
id = "op7"
tool_id = 3

[zenoh]
connect = ["tcp/127.0.0.1:7447"]

[openprotocol]
host = "192.0.2.10"

[recorder]
folder = "recordings"
"""


def write(tmp_path: Path, text: str, name: str = "ctrl.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def refusal(path: Path) -> str:
    with pytest.raises(ConfigError) as caught:
        load_any_station(path)
    return str(caught.value)


def test_the_shipped_controller_station_loads_as_one() -> None:
    station = load_any_station(CONTROLLER_FILE)
    assert isinstance(station, ControllerStation)
    assert (station.station_id, station.config.station.tool_id) == ("op1", 11)
    assert station.config.openprotocol.host == "192.0.2.10"
    pset = station.config.program(1)
    assert pset.name == "M6 cover screw, 25 Nm"
    assert pset.window("torque") == (23.0, 27.0)
    assert station.sensor_range == CONTRACT_RANGE
    assert station.recordings_folder == (CONFIG.parent / "recordings").resolve()
    # the shipped CAN station is still a CAN station, for either loader
    assert isinstance(load_any_station(STATION_FILE), LoadedStation)
    assert isinstance(load_station(STATION_FILE), LoadedStation)


def test_a_minimal_controller_station_needs_no_psets_and_an_unknown_pset_is_a_key_error(
    tmp_path: Path,
) -> None:
    station = load_any_station(write(tmp_path, MINIMAL))
    assert isinstance(station, ControllerStation)
    assert station.config.programs == []
    assert station.config.quality.cpk_min == 1.33  # [quality] optional, its defaults
    with pytest.raises(KeyError, match=r"no pset 4 in station op7 \(known: none\)"):
        station.config.program(4)


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        (
            'joint = "joints/paper-section-5-2.toml"\n',
            "station.joint: not used by a controller station ([openprotocol] without [can]): "
            "the controller's joint is neither simulated nor modelled; remove it",
        ),
        (
            "has_force_sensor = false\n",
            "station.has_force_sensor: not used by a controller station ([openprotocol] "
            "without [can]): a controller reports torque and angle, no preload; remove it",
        ),
    ],
)
def test_station_keys_of_a_can_station_are_refused_by_name(
    tmp_path: Path, extra: str, expected: str
) -> None:
    path = write(tmp_path, MINIMAL.replace("tool_id = 3\n", "tool_id = 3\n" + extra))
    assert refusal(path) == f"{path}: {expected}"


def test_a_pset_with_motor_speed_and_limits_is_refused_naming_each_key(tmp_path: Path) -> None:
    pset = (
        "\n[[programs]]\nid = 1\nname = 'M14'\nmotor_speed_rad_s = 0.5\nmax_torque_nm = 320.0\n"
        "torque_max_nm = 240.0\nforce_min_n = 53000.0\n"
    )
    path = write(tmp_path, MINIMAL + pset + "\n[rig]\nseed = 7\n")
    assert refusal(path) == (
        f"{path}: rig: not used by a controller station ([openprotocol] without [can]): the "
        "simulated tool's settings; a controller station's tool is real (the simulated "
        "controller plays a CAN station file, e.g. config/station.toml); remove it; "
        "programs[0].motor_speed_rad_s, programs[0].max_torque_nm: not used by a controller "
        "station ([openprotocol] without [can]): the controller keeps its pset's target, speed "
        "and limits itself (a pset here has id, name and torque and angle windows); remove "
        "them; programs[0].force_min_n: not used by a controller station ([openprotocol] "
        "without [can]): a controller reports torque and angle, no preload; remove it"
    )


def test_a_predictor_section_is_refused(tmp_path: Path) -> None:
    path = write(tmp_path, MINIMAL + '\n[predictor]\nplacement = "edge"\n')
    assert refusal(path).startswith(
        f"{path}: predictor: not used by a controller station ([openprotocol] without [can]): "
        "the controller stops its own tool"
    )


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        (
            MINIMAL.replace('host = "192.0.2.10"', 'hots = "192.0.2.10"'),
            "openprotocol.hots: unknown key; expected one of: header_fill, host",
        ),
        (
            MINIMAL.replace('[zenoh]\nconnect = ["tcp/127.0.0.1:7447"]\n', ""),
            "zenoh: Field required",
        ),
        (
            MINIMAL + "\n[[programs]]\nid = 1000\nname = 'x'\n",
            "programs[0].id: Input should be less than or equal to 999 (got 1000)",
        ),
        (
            MINIMAL + "\n[[programs]]\nid = 1\nname = 'x'\ntorque_min_nm = 30.0\n"
            "torque_max_nm = 20.0\n",
            "programs[0]: torque_min_nm 30 Nm is not below torque_max_nm 20 Nm: no run could be OK",
        ),
        (
            MINIMAL + "\n[[programs]]\nid = 1\nname = 'x'\ntorque_max_nm = 9000.0\n",
            "programs[0]: torque_max_nm: 9000 Nm is beyond what the sensor can report "
            "(-8388.61 to 8388.61 Nm)",
        ),
        (
            MINIMAL + "\n[[programs]]\nid = 2\nname = 'a'\n\n[[programs]]\nid = 2\nname = 'b'\n",
            "pset ids must be unique (got [2, 2])",
        ),
        (
            MINIMAL + "\n[[programs]]\nid = 2\n",
            "programs[0].name: Field required",
        ),
        (
            MINIMAL.replace('folder = "recordings"', 'folder = "recordings"\nfolde = "x"'),
            "recorder.folde: unknown key",
        ),
    ],
)
def test_a_bad_controller_station_names_file_and_key(
    tmp_path: Path, text: str, expected: str
) -> None:
    path = write(tmp_path, text)
    message = refusal(path)
    assert message.startswith(f"{path}: "), message
    assert expected in message, message


def test_a_can_station_is_refused_as_a_controller_station_only_by_what_needs_can(
    tmp_path: Path,
) -> None:
    """A CAN service (rig, acquisition, predictor, simulate, predict) given a controller
    station's file says what it needs and what runs such a station instead."""
    path = write(tmp_path, MINIMAL)
    with pytest.raises(ConfigError) as caught:
        load_station(path)
    assert str(caught.value) == (
        f"{path}: can: a controller station ([openprotocol] without [can]) has no CAN bus, "
        "joint or motor; this needs a CAN station's file ([can], station.joint, programs with "
        "motor speed and hard limits, e.g. config/station.toml). A controller station runs "
        f"its bridge: boltwatch serve openprotocol --config {path}"
    )


def test_a_can_station_file_without_can_and_openprotocol_fails_as_it_always_did(
    tmp_path: Path,
) -> None:
    text = re.sub(r"^\[can\]\n.*?(?=^\[zenoh\])", "", STATION_FILE.read_text(), flags=re.M | re.S)
    path = write(tmp_path, text, "station.toml")
    message = refusal(path)
    assert message == f"{path}: can: Field required"
    empty = write(tmp_path, "", "empty.toml")
    assert refusal(empty) == f"{empty}: station, can, zenoh, programs, recorder: Field required"


def test_a_line_serves_both_kinds_once_each_on_one_router(tmp_path: Path) -> None:
    can_file = tmp_path / "st1.toml"
    can_file.write_text(
        STATION_FILE.read_text()
        .replace('"joints/', f'"{CONFIG}/joints/')
        .replace('"can/', f'"{CONFIG}/can/')
    )
    controller = write(tmp_path, MINIMAL)
    stations = load_any_line([can_file, controller])
    assert [type(s).__name__ for s in stations] == ["LoadedStation", "ControllerStation"]
    twin = write(tmp_path, MINIMAL.replace('id = "op7"', 'id = "st1"'), "twin.toml")
    with pytest.raises(ConfigError, match=r"station\.id: both are station 'st1'"):
        load_any_line([can_file, twin])
    other_router = write(
        tmp_path, MINIMAL.replace(":7447", ":7448").replace("op7", "op8"), "other.toml"
    )
    with pytest.raises(ConfigError, match="zenoh: the sections differ"):
        load_any_line([controller, other_router])
