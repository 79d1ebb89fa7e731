"""docker-compose.yml and the Dockerfile, checked by parsing (no Docker engine here)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import yaml

from services.cli.main import build_parser
from shared.config import load_station
from tests.paths import REPO

COMPOSE = yaml.safe_load((REPO / "docker-compose.yml").read_text())
SERVICES: dict[str, Any] = COMPOSE["services"]


def host_path(container_path: str, volumes: list[str]) -> Path:
    """Map a path inside the container to the repository through the service's mounts."""
    for volume in volumes:
        source, target = volume.split(":")[:2]
        if container_path.startswith(target + "/"):
            return (REPO / source / container_path[len(target) + 1 :]).resolve()
    raise AssertionError(f"{container_path} is not under any mount of {volumes}")


def test_every_part_of_the_line_is_there() -> None:
    assert {"router", "rig", "acquisition", "predictor", "recorder"} <= set(SERVICES)


@pytest.mark.parametrize("name", sorted(SERVICES))
def test_command_is_a_valid_boltwatch_command(name: str) -> None:
    service = SERVICES[name]
    args = build_parser().parse_args(service["command"])  # SystemExit on an unknown command
    assert args.command == "serve"
    assert args.service == name
    for volume in service["volumes"]:
        source = volume.split(":")[0]
        assert (REPO / source).exists(), f"{name}: mounted {source} does not exist"
    if name != "router":
        files = args.config if isinstance(args.config, list) else [args.config]
        for file in files:
            station = load_station(host_path(str(file), service["volumes"]))
            assert station.config.zenoh.connect == ["tcp/router:7447"]
    for dependency in service.get("depends_on", []):
        assert dependency in SERVICES


def test_dockerfile_installs_the_package_and_runs_the_cli() -> None:
    text = (REPO / "Dockerfile").read_text()
    assert "pip install --no-cache-dir ." in text
    assert 'ENTRYPOINT ["boltwatch"]' in text
    for copied in ("shared", "services", "pyproject.toml"):
        assert copied in text and (REPO / copied).exists()
