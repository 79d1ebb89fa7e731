"""docker-compose.line2.yml: a second line of the plant, merged with docker-compose.yml.

Checked by parsing, as tests/unit/deployment/test_compose.py checks the line (no Docker
engine here): line 2's router meshes with line 1's, line 2's services connect
to line 2's router only, its recorder serves its own stations only and writes
its own required recordings folder, every command and health check parses
with the CLI, every dependency waits for health, and no station of the plant
shares a tool id, CAN port or seed with another.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from services.cli.main import build_parser
from shared.config import load_line
from tests.support.compose_layout import (
    BASE_FILE,
    MissingVariableError,
    config_files,
    host_path,
    load_merged,
    split_volume,
)
from tests.support.paths import REPO

LINE2_FILE = REPO / "docker-compose.line2.yml"
ENV = {
    "BOLTWATCH_RECORDINGS": "/srv/line1",
    "BOLTWATCH_RECORDINGS_LINE2": "/srv/line2",
    "BOLTWATCH_CERTS": "/srv/certs",  # line 1's OPC UA server's files
}
MERGED: dict[str, Any] = load_merged([BASE_FILE, LINE2_FILE], ENV)["services"]
LINE2 = ("router-line2", "recorder-line2", "acquisition-st3", "rig-st3")
RECORDINGS = "/var/lib/boltwatch/recordings"


def station_files(name: str) -> list[Path]:
    service = MERGED[name]
    return [host_path(file, service["volumes"]) for file in config_files(service["command"])]


def test_line_two_is_added_and_line_one_is_unchanged() -> None:
    line1 = load_merged([BASE_FILE], ENV)["services"]
    assert set(MERGED) == set(line1) | set(LINE2)
    assert all(MERGED[name] == line1[name] for name in line1)


def test_line_twos_router_meshes_with_line_ones() -> None:
    args = build_parser().parse_args(MERGED["router-line2"]["command"])
    assert args.listen == ["tcp/0.0.0.0:7447"]
    assert args.connect == ["tcp/router:7447"]  # line 1's router, by its service name


@pytest.mark.parametrize("name", LINE2)
def test_line_twos_services_use_its_own_router_files_and_recordings(name: str) -> None:
    service = MERGED[name]
    args = build_parser().parse_args(service["command"])
    assert (args.command, args.service) == ("serve", name.split("-", maxsplit=1)[0])
    mounts = {target: source for source, target in map(split_volume, service["volumes"])}
    assert mounts[RECORDINGS] == "/srv/line2"  # never line 1's folder and ledger
    if name == "router-line2":
        return
    stations = load_line(station_files(name))
    assert [s.station_id for s in stations] == ["st3"]  # line 2's recorder: its station only
    for station in stations:
        assert station.config.zenoh.connect == ["tcp/router-line2:7447"]


@pytest.mark.parametrize("name", LINE2)
def test_line_twos_health_checks_parse_and_dependencies_wait_for_health(name: str) -> None:
    service = MERGED[name]
    test = service["healthcheck"]["test"]
    assert test[:2] == ["CMD", "boltwatch"]
    args = build_parser().parse_args(test[2:])
    assert args.command == "health" and args.service == name.split("-", maxsplit=1)[0]
    checked = [host_path(str(f), service["volumes"]) for f in args.config]
    assert all(s.config.zenoh.connect == ["tcp/router-line2:7447"] for s in load_line(checked))
    for dependency, condition in service.get("depends_on", {}).items():
        assert dependency in LINE2, f"{name} waits for line 1's {dependency}"
        assert condition == {"condition": "service_healthy"}


def test_no_two_stations_of_the_plant_share_a_tool_bus_or_seed() -> None:
    stations = [
        *load_line(station_files("recorder")),
        *load_line(station_files("recorder-line2")),
    ]
    assert [s.station_id for s in stations] == ["st1", "st2", "st3"]
    for value in (
        lambda s: s.config.station.tool_id,
        lambda s: s.config.can.port,
        lambda s: s.config.rig.seed,
    ):
        assert len({value(s) for s in stations}) == len(stations)


def test_line_twos_recordings_folder_is_required() -> None:
    with pytest.raises(MissingVariableError, match="BOLTWATCH_RECORDINGS_LINE2"):
        load_merged([BASE_FILE, LINE2_FILE], ENV | {"BOLTWATCH_RECORDINGS_LINE2": ""})
