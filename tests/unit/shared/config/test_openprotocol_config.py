"""The ``[openprotocol]`` section of a station file: optional, defaults stated,
the shipped example loads, each bad value refused naming the file and the key."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from shared.config import load_station
from shared.errors import ConfigError
from tests.support.config_files import write_station
from tests.support.paths import STATION_FILE


def example_sections() -> str:
    """The commented example of the shipped station file, its TOML lines uncommented."""
    lines = STATION_FILE.read_text().splitlines()
    start = lines.index("# [openprotocol]")
    toml = [line.removeprefix("# ") for line in lines[start:]]
    return "\n".join(line for line in toml if re.match(r"\[|\w+ = ", line))


def test_a_station_without_the_section_has_none_and_the_simulated_controller_its_defaults(
    tmp_path: Path,
) -> None:
    config = load_station(write_station(tmp_path, "")).config
    assert config.openprotocol is None
    assert (config.rig.openprotocol.ack_timeout_s, config.rig.openprotocol.link_timeout_s) == (
        5.0,
        15.0,
    )


def test_the_shipped_example_loads_with_its_stated_defaults(tmp_path: Path) -> None:
    config = load_station(write_station(tmp_path, "\n" + example_sections() + "\n")).config
    bridge = config.openprotocol
    assert bridge is not None
    assert bridge.host == "192.0.2.10"
    defaults = load_station(
        write_station(tmp_path, '\n[openprotocol]\nhost = "192.0.2.10"\n')
    ).config.openprotocol
    assert bridge == defaults  # the example states every default as it is
    assert (bridge.port, bridge.keep_alive_s, bridge.result_revision) == (4545, 10.0, 2)
    assert (bridge.reconnect_min_s, bridge.reconnect_max_s) == (1.0, 30.0)
    assert (bridge.trace_byte_order, bridge.header_fill, bridge.timezone) == (
        "auto",
        "spaces",
        "UTC",
    )
    assert bridge.traces is True


def test_a_controller_time_zone_by_its_iana_name(tmp_path: Path) -> None:
    section = '\n[openprotocol]\nhost = "pf6000.plant.local"\ntimezone = "Europe/Berlin"\n'
    bridge = load_station(write_station(tmp_path, section)).config.openprotocol
    assert bridge is not None and bridge.timezone == "Europe/Berlin"


@pytest.mark.parametrize(
    ("section", "expected"),
    [
        ("port = 4545", "openprotocol.host: Field required"),
        ('host = ""', "openprotocol.host: String should have at least 1 character"),
        ('host = "a b"', "openprotocol.host: String should match pattern"),
        ('host = "h"\nport = 0', "openprotocol.port: Input should be greater than or equal to 1"),
        ('host = "h"\nport = 70000', "openprotocol.port: Input should be less than or equal to"),
        (
            'host = "h"\nkeep_alive_s = 15',
            "openprotocol.keep_alive_s: Input should be less than 15",
        ),
        (
            'host = "h"\nkeep_alive_s = 0',
            "openprotocol.keep_alive_s: Input should be greater than 0",
        ),
        (
            'host = "h"\nreconnect_min_s = 0',
            "openprotocol.reconnect_min_s: Input should be greater",
        ),
        (
            'host = "h"\nreconnect_max_s = -1',
            "openprotocol.reconnect_max_s: Input should be greater",
        ),
        (
            'host = "h"\nreconnect_min_s = 40',
            "reconnect_min_s 40 s is above reconnect_max_s 30 s",
        ),
        (
            'host = "h"\nresult_revision = 0',
            "openprotocol.result_revision: Input should be greater",
        ),
        (
            'host = "h"\ntrace_byte_order = "middle"',
            "openprotocol.trace_byte_order: Input should be 'auto', 'big' or 'little'",
        ),
        (
            'host = "h"\nheader_fill = "nul"',
            "openprotocol.header_fill: Input should be 'spaces' or 'zeros'",
        ),
        (
            'host = "h"\ntimezone = "Mars/Olympus"',
            "openprotocol.timezone: not a time zone zoneinfo knows",
        ),
        ('host = "h"\ntimezone = "../etc"', "openprotocol.timezone: not a time zone zoneinfo"),
        ('host = "h"\ntraces = "maybe"', "openprotocol.traces: Input should be a valid boolean"),
        ('host = "h"\nport_nr = 1', "openprotocol.port_nr: unknown key; expected one of: "),
    ],
)
def test_each_bad_value_is_refused_naming_file_and_key(
    tmp_path: Path, section: str, expected: str
) -> None:
    path = write_station(tmp_path, f"\n[openprotocol]\n{section}\n")
    with pytest.raises(ConfigError) as caught:
        load_station(path)
    message = str(caught.value)
    assert message.startswith(f"{path}: ")
    assert expected in message
    assert "\n" not in message


@pytest.mark.parametrize(
    ("section", "expected"),
    [
        ("ack_timeout_s = 0", "rig.openprotocol.ack_timeout_s: Input should be greater than 0"),
        ("link_timeout_s = -1", "rig.openprotocol.link_timeout_s: Input should be greater than"),
        ("resends = 3", "rig.openprotocol.resends: unknown key; expected one of: ack_timeout_s"),
    ],
)
def test_the_simulated_controllers_side_is_checked_too(
    tmp_path: Path, section: str, expected: str
) -> None:
    path = write_station(tmp_path, f"\n[rig.openprotocol]\n{section}\n")
    with pytest.raises(ConfigError) as caught:
        load_station(path)
    assert str(caught.value).startswith(f"{path}: ") and expected in str(caught.value)


def test_a_keep_alive_the_simulated_controller_would_not_wait_for_is_refused(
    tmp_path: Path,
) -> None:
    sections = '\n[openprotocol]\nhost = "h"\nkeep_alive_s = 8\n[rig.openprotocol]\n'
    path = write_station(tmp_path, sections + "link_timeout_s = 8\n")
    with pytest.raises(ConfigError) as caught:
        load_station(path)
    assert str(caught.value) == (
        f"{path}: openprotocol.keep_alive_s: 8 s is not below rig.openprotocol.link_timeout_s "
        "8 s: the simulated controller would drop the link between two keep-alives"
    )
    assert load_station(write_station(tmp_path, sections + "link_timeout_s = 9\n"))
