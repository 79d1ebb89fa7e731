"""Line configuration: several station files for one process, stations derived from one."""

from __future__ import annotations

import shutil
import tomllib
from pathlib import Path

import pytest

from shared.config import derive_stations, derived_ids, dumps, load_line, load_station
from shared.errors import ConfigError
from tests.support.paths import CONFIG, STATION_FILE
from tests.support.station_files import write_station


def test_derived_ids_count_up_from_the_trailing_number() -> None:
    assert derived_ids("st1", 3) == ["st1", "st2", "st3"]
    assert derived_ids("st5", 2) == ["st5", "st6"]
    assert derived_ids("press", 2) == ["press1", "press2"]
    assert derived_ids("line-a", 1) == ["line-a1"]


def test_derived_stations_are_isolated_and_load(tmp_path: Path) -> None:
    paths = derive_stations(STATION_FILE, 5, tmp_path / "stations")
    stations = [load_station(path) for path in paths]
    base = load_station(STATION_FILE)
    assert [s.station_id for s in stations] == ["st1", "st2", "st3", "st4", "st5"]
    assert [path.name for path in paths] == [f"st{i}.toml" for i in range(1, 6)]
    ports = [s.config.can.port for s in stations]
    assert base.config.can.port is not None
    assert ports == [base.config.can.port + i for i in range(5)]
    assert len({s.config.station.tool_id for s in stations}) == 5
    assert [s.config.rig.seed for s in stations] == [7, 8, 9, 10, 11]
    for station in stations:  # the same line, joint, programs and recordings
        assert station.config.zenoh == base.config.zenoh
        assert station.config.programs == base.config.programs
        assert station.config.predictor == base.config.predictor
        assert station.joint == base.joint
        assert station.joint_path == base.joint_path.resolve()
        assert station.dbc_path == base.dbc_path.resolve()
        assert station.recordings_folder == base.recordings_folder.resolve()
        assert station.config.can.channel == base.config.can.channel
    assert [s.station_id for s in load_line(paths)] == [s.station_id for s in stations]


def test_one_derived_station_is_the_base_station(tmp_path: Path) -> None:
    (path,) = derive_stations(STATION_FILE, 1, tmp_path)
    derived, base = load_station(path), load_station(STATION_FILE)
    assert derived.config.station.id == base.config.station.id
    assert derived.config.can == base.config.can.model_copy(update={"dbc": derived.dbc_path})


def test_derivation_refuses_ports_beyond_the_range(tmp_path: Path) -> None:
    station = write_station(tmp_path, replacements={"port = ": "port = 65534 #"})
    with pytest.raises(ConfigError, match=r"can\.port: 65534 \+ 2 stations exceeds 65535"):
        derive_stations(station, 3, tmp_path / "out")
    with pytest.raises(ConfigError, match="at least 1"):
        derive_stations(station, 0, tmp_path / "out")


def test_a_station_twice_is_an_error_naming_both_files(tmp_path: Path) -> None:
    first = write_station(tmp_path)
    (tmp_path / "b").mkdir()
    second = write_station(tmp_path / "b")
    text = second.read_text().replace(
        f"tcp/127.0.0.1:{_port(second)}", f"tcp/127.0.0.1:{_port(first)}"
    )
    second.write_text(text)
    with pytest.raises(ConfigError) as err:
        load_line([first, second])
    assert str(first) in str(err.value) and str(second) in str(err.value)
    assert "'st1'" in str(err.value)


def test_different_zenoh_sections_are_an_error_naming_both_files(tmp_path: Path) -> None:
    first = write_station(tmp_path, zenoh_port=7001)
    (tmp_path / "b").mkdir()  # another router: two free ports drawn apart may be the same one
    second = write_station(
        tmp_path / "b", zenoh_port=7002, replacements={'id = "st1"': 'id = "st2"'}
    )
    with pytest.raises(ConfigError, match="zenoh: the sections differ") as err:
        load_line([first, second])
    assert str(first) in str(err.value) and str(second) in str(err.value)


def test_no_station_file_is_an_error() -> None:
    with pytest.raises(ConfigError, match="no station file"):
        load_line([])


def test_toml_writer_round_trips_a_station_file() -> None:
    document = tomllib.loads(STATION_FILE.read_text())
    assert tomllib.loads(dumps(document)) == document
    tricky = {"a": {"quote": 'say "hi"\n', "list": [1.5, -2.0, True], "x y": 1}}
    assert tomllib.loads(dumps(tricky)) == tricky


def _port(path: Path) -> str:
    text = path.read_text()
    return text.split("tcp/127.0.0.1:")[1].split('"')[0]


def test_derived_stations_keep_every_relative_path_of_the_base(tmp_path: Path) -> None:
    """The derived files live in another folder: a program's own joint and the TLS files,
    relative to the base station file, must still name the same files."""
    base_folder = tmp_path / "base"
    shutil.copytree(CONFIG, base_folder)
    (base_folder / "security" / "ca.pem").write_text("not parsed at load")
    base_file = base_folder / "station.toml"
    text = base_file.read_text()
    text = text.replace(
        "motor_speed_rad_s = 1.0",
        'motor_speed_rad_s = 1.0\njoint = "joints/paper-section-3-4.toml"',
    )
    text = text.replace("[zenoh]\n", '[zenoh]\ntls_root_ca = "security/ca.pem"\n')
    text = text.replace("tcp/127.0.0.1:7447", "tls/127.0.0.1:7447")
    base_file.write_text(text)
    base = load_station(base_file)
    assert base.config.zenoh.tls_root_ca == base_folder / "security" / "ca.pem"
    for path in derive_stations(base_file, 2, tmp_path / "derived"):
        derived = load_station(path)
        assert derived.config.zenoh == base.config.zenoh
        assert derived.joint_of(2) == base.joint_of(2) != base.joint
