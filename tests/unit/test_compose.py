"""docker-compose.yml and the Dockerfile, checked by parsing (no Docker engine here).

The line layout: one router, one recorder for the line (every station file),
an optional Rerun viewer (profile), and per station an acquisition, a rig
and a predictor with that station's own file.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest
import yaml

from services.cli.main import build_parser
from shared.config import load_line, load_station
from tests.paths import REPO

COMPOSE_TEXT = (REPO / "docker-compose.yml").read_text()
COMPOSE = yaml.safe_load(COMPOSE_TEXT)
SERVICES: dict[str, Any] = COMPOSE["services"]
STATIONS = ("st1", "st2")
PER_STATION = ("acquisition", "rig", "predictor")
VARIABLE = re.compile(r"\$\{([^}]*)\}")
MOUNT = re.compile(r"(.+):(/[^:]*)(?::ro|:rw)?")


def split_volume(volume: str) -> tuple[str, str]:
    """``SOURCE:TARGET[:ro]`` -> (SOURCE, TARGET); SOURCE may be ``${VAR:?message}``."""
    match = MOUNT.fullmatch(volume)
    assert match, f"not a SOURCE:TARGET mount: {volume}"
    return match.group(1), match.group(2)


def host_path(container_path: str, volumes: list[str]) -> Path:
    """Map a path inside the container to the repository through the service's mounts."""
    for volume in volumes:
        source, target = split_volume(volume)
        if container_path.startswith(target + "/"):
            assert source.startswith("./"), f"{container_path} is not mounted from the repository"
            return (REPO / source / container_path[len(target) + 1 :]).resolve()
    raise AssertionError(f"{container_path} is not under any mount of {volumes}")


def served_role(name: str) -> str:
    """``acquisition-st1`` -> ``acquisition``; ``viewer`` is a recorder."""
    return "recorder" if name == "viewer" else name.split("-", maxsplit=1)[0]


def health_role(name: str) -> str:
    """The health token a service holds: the viewer is a recorder that says ``viewer``."""
    return "viewer" if name == "viewer" else served_role(name)


def station_files(name: str) -> list[Path]:
    service = SERVICES[name]
    args = build_parser().parse_args(service["command"])
    files = args.config if isinstance(args.config, list) else [args.config]
    return [host_path(str(file), service["volumes"]) for file in files]


def test_the_line_layout_is_there() -> None:
    expected = {"router", "recorder", "viewer"} | {
        f"{role}-{station}" for role in PER_STATION for station in STATIONS
    }
    assert set(SERVICES) == expected
    assert SERVICES["viewer"]["profiles"] == ["viewer"]
    for station in STATIONS:  # the simulated bus is multicast inside the station's netns
        assert SERVICES[f"rig-{station}"]["network_mode"] == f"service:acquisition-{station}"


@pytest.mark.parametrize("name", sorted(SERVICES))
def test_command_is_a_valid_boltwatch_command(name: str) -> None:
    service = SERVICES[name]
    args = build_parser().parse_args(service["command"])  # SystemExit on an unknown command
    assert args.command == "serve"
    assert args.service == served_role(name)
    for volume in service["volumes"]:
        source, _ = split_volume(volume)
        if source.startswith("./"):
            assert (REPO / source).exists(), f"{name}: mounted {source} does not exist"
    assert getattr(args, "view_only", False) == (name == "viewer"), "only the viewer is a view"
    if name == "router":
        return
    stations = load_line(station_files(name))  # each loads; one id per file, one router
    for station in stations:
        assert station.config.zenoh.connect == ["tcp/router:7447"]
    ids = [station.station_id for station in stations]
    if name in ("recorder", "viewer"):
        assert ids == list(STATIONS), "the line's recorder serves every station"
    else:
        assert ids == [name.split("-", 1)[1]], f"{name} must serve only its own station"


def test_station_files_are_isolated_from_each_other() -> None:
    stations = [load_station(path) for path in station_files("recorder")]
    assert len({s.config.station.tool_id for s in stations}) == len(stations)
    assert len({s.config.can.port for s in stations}) == len(stations)
    assert len({s.config.rig.seed for s in stations}) == len(stations)


@pytest.mark.parametrize("name", sorted(SERVICES))
def test_health_checks_parse_and_dependencies_wait_for_health(name: str) -> None:
    service = SERVICES[name]
    test = service["healthcheck"]["test"]
    assert test[:2] == ["CMD", "boltwatch"]
    args = build_parser().parse_args(test[2:])
    assert args.command == "health" and args.service == health_role(name)
    if name != "router":
        checked = [host_path(str(f), service["volumes"]) for f in args.config]
        assert checked == station_files(name)
    depends_on = service.get("depends_on", {})
    assert isinstance(depends_on, dict), f"{name}: depends_on needs conditions"
    for dependency, condition in depends_on.items():
        assert dependency in SERVICES, f"{name} depends on unknown {dependency}"
        assert condition == {"condition": "service_healthy"}, f"{name} -> {dependency}"
        assert "healthcheck" in SERVICES[dependency], f"{dependency} has no health check"


def test_required_variables_fail_loudly() -> None:
    variables = VARIABLE.findall(COMPOSE_TEXT)
    assert variables, "the recordings folder must come from BOLTWATCH_RECORDINGS"
    for variable in variables:
        name, _, message = variable.partition(":?")
        assert message.strip(), f"${{{variable}}} must be required (${{{name}:?message}})"
    assert any(v.startswith("BOLTWATCH_RECORDINGS:?") for v in variables)


def test_dockerfile_installs_the_package_and_runs_the_cli() -> None:
    text = (REPO / "Dockerfile").read_text()
    assert "pip install --no-cache-dir ." in text
    assert 'ENTRYPOINT ["boltwatch"]' in text
    for copied in ("shared", "services", "pyproject.toml"):
        assert copied in text and (REPO / copied).exists()
