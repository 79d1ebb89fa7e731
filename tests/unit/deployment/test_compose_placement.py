"""Where each compose station decides, and the documented line predictor, checked by parsing.

A station file's ``[predictor] placement`` says where its predictor runs.
"edge" (the compose files' layout): inside ``acquisition-stK``, so there is no
predictor service for the station, and its rig waits for its acquisition
(whose health check passing means its predictor's token is there too) and
for the recorder. "line": a ``serve predictor`` service decides for it, and
the rig waits for that service as well. The comments of docker-compose.yml
and docker-compose.tls.yml show how to add a line predictor; their snippets
are spliced into the files here and must pass the same checks.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path
from typing import Any

import pytest
import yaml

from services.cli.main import build_parser
from shared.config import load_line
from tests.support.compose_layout import (
    BASE_FILE,
    IDENTITY,
    TLS_FILE,
    common_name,
    config_files,
    host_path,
    load_merged,
    make_compose_certs,
)

STATIONS = ("st1", "st2")
HEALTHY = {"condition": "service_healthy"}
ENV = {"BOLTWATCH_CERTS": "/srv/certs", "BOLTWATCH_RECORDINGS": "/srv/recordings"}


def station_ids(service: dict[str, Any]) -> list[str]:
    files = [host_path(file, service["volumes"]) for file in config_files(service["command"])]
    return [station.station_id for station in load_line(files)]


def placement(services: dict[str, Any], station: str) -> str:
    acquisition = services[f"acquisition-{station}"]
    files = [host_path(f, acquisition["volumes"]) for f in config_files(acquisition["command"])]
    return load_line(files)[0].config.predictor.placement


def predictor_services(services: dict[str, Any], station: str) -> list[str]:
    """The services that run ``serve predictor`` for ``station``."""
    return [
        name
        for name, service in services.items()
        if build_parser().parse_args(service["command"]).service == "predictor"
        and station in station_ids(service)
    ]


def check_where_the_station_decides(services: dict[str, Any], station: str, where: str) -> None:
    deciders = predictor_services(services, station)
    rig_waits_for = services[f"rig-{station}"]["depends_on"]
    if where == "edge":
        assert deciders == [], f"{station} decides in acquisition-{station}: no predictor service"
        assert rig_waits_for == {f"acquisition-{station}": HEALTHY, "recorder": HEALTHY}
        return
    assert deciders == [f"predictor-{station}"], f"{station} needs one line predictor"
    assert rig_waits_for == {
        f"acquisition-{station}": HEALTHY,
        f"predictor-{station}": HEALTHY,
        "recorder": HEALTHY,
    }
    predictor = services[deciders[0]]
    assert predictor["depends_on"] == {"router": HEALTHY}
    health = predictor["healthcheck"]["test"]
    assert health[:2] == ["CMD", "boltwatch"]
    checked = build_parser().parse_args(health[2:])
    assert checked.service == "predictor"
    assert [str(f) for f in checked.config] == config_files(predictor["command"])


def commented_service(text: str, name: str) -> str:
    """The service ``name`` that a compose file's comments show, uncommented (YAML)."""
    lines = text.splitlines()
    block = []
    for line in lines[lines.index(f"#   {name}:") :]:
        if not line.startswith("#") or not line[1:].strip():
            break
        block.append(line[2:])  # "#   predictor-st1:" -> "  predictor-st1:"
    return "\n".join(block) + "\n"


def with_service(text: str, service: str) -> str:
    """A compose file's text with ``service`` (YAML under ``services:``) added."""
    head, tail = text.split("\nservices:\n", 1)
    return f"{head}\nservices:\n{service}\n{tail}"


@pytest.mark.parametrize("station", STATIONS)
def test_each_station_decides_in_its_acquisition(station: str) -> None:
    services = yaml.safe_load(BASE_FILE.read_text())["services"]
    assert placement(services, station) == "edge", "the compose line is the edge layout"
    check_where_the_station_decides(services, station, "edge")


def test_the_documented_line_predictor_passes_the_same_checks(tmp_path: Path) -> None:
    text = BASE_FILE.read_text()
    spliced = yaml.safe_load(with_service(text, commented_service(text, "predictor-st1")))
    services = spliced["services"]
    wait = re.search(r"with `(predictor-st1: [^`]*)` in rig-st1's depends_on", text)
    assert wait, "docker-compose.yml must say what the rig waits for with a line predictor"
    services["rig-st1"]["depends_on"] |= yaml.safe_load(wait.group(1))
    check_where_the_station_decides(services, "st1", "line")
    predictor = services["predictor-st1"]
    for key in ("image", "volumes", "restart"):  # the line's common settings (x-boltwatch)
        assert predictor[key] == services["acquisition-st1"][key]
    assert station_ids(predictor) == ["st1"]
    # With TLS: the override's snippet mounts the line predictor's own identity.
    base, tls = tmp_path / "docker-compose.yml", tmp_path / "docker-compose.tls.yml"
    base.write_text(yaml.safe_dump(spliced))
    tls_text = TLS_FILE.read_text()
    tls.write_text(with_service(tls_text, commented_service(tls_text, "predictor-st1")))
    merged = load_merged([base, tls], ENV)["services"]["predictor-st1"]
    assert merged["volumes"][-1] == f"{ENV['BOLTWATCH_CERTS']}/st1-predictor:{IDENTITY}:ro"
    tls_station = "/etc/boltwatch/compose/tls/station1.toml"
    assert config_files(merged["command"]) == [tls_station]
    assert config_files(merged["healthcheck"]["test"][2:]) == [tls_station]
    made = re.search(r"EXTRA_IDENTITIES=(\S+) config/security/make-compose-certs\.sh", tls_text)
    assert made and made.group(1) == "st1-predictor", "the TLS file says how to make its identity"


@pytest.mark.skipif(shutil.which("openssl") is None, reason="needs the openssl CLI")
def test_extra_identities_are_made_beside_the_compose_ones(tmp_path: Path) -> None:
    certs = tmp_path / "certs"
    make_compose_certs(certs, extra_identities=("st1-predictor",))
    folder = certs / "st1-predictor"
    assert {p.name for p in folder.iterdir()} == {"ca.pem", "identity.pem", "identity.key"}
    assert common_name(folder / "identity.pem") == "st1-predictor"
