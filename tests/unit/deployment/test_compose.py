"""docker-compose.yml and the Dockerfile, checked by parsing (no Docker engine here).

The line layout: one router, one recorder for the line (every station file),
an optional Rerun viewer (profile), the line's page and its OPC UA server, and
per station an acquisition (which holds the station's predictor: placement
"edge") and a rig with that station's own file; the line's page and the OPC UA
server read the recorder's results store. Where each station's predictor runs:
tests/unit/deployment/test_compose_placement.py; the OPC UA server's certificates:
test_compose_opcua.py; the image's OPC UA models: test_image_models.py.
"""

from __future__ import annotations

import json
import re
import shutil
import stat
from pathlib import Path
from typing import Any

import pytest
import yaml

from services.cli.main import build_parser
from services.dashboard.part_search import stores_of
from services.router.access_control import line_access_control
from services.router.service import router_config
from shared.config import load_line, load_station, resolve_relative
from shared.contract import channels, keys
from tests.support.access_rules import put_keys_granted
from tests.support.compose_layout import (
    BASE_FILE,
    CERTS_SCRIPT,
    IDENTITY,
    TLS_FILE,
    ContainerFiles,
    MissingVariableError,
    certificate_field,
    common_name,
    config_files,
    host_path,
    load_merged,
    make_compose_certs,
    split_volume,
)
from tests.support.paths import REPO

COMPOSE_TEXT = (REPO / "docker-compose.yml").read_text()
COMPOSE = yaml.safe_load(COMPOSE_TEXT)
SERVICES: dict[str, Any] = COMPOSE["services"]
STATIONS = ("st1", "st2")
PER_STATION = ("acquisition", "rig")
VARIABLE = re.compile(r"\$\{([^}]*)\}")


#: services of the whole line (every station file); the others serve one station
LINE_WIDE = ("recorder", "viewer", "dashboard", "opcua")


def served_role(name: str) -> str:
    """``acquisition-st1`` -> ``acquisition``; ``viewer`` is a recorder."""
    return "recorder" if name == "viewer" else name.split("-", maxsplit=1)[0]


def health_role(name: str) -> str:
    """The health token a service holds: the viewer is a recorder that says ``viewer``."""
    return "viewer" if name == "viewer" else served_role(name)


def station_files(name: str) -> list[Path]:
    service = SERVICES[name]
    return [host_path(file, service["volumes"]) for file in config_files(service["command"])]


def test_the_line_layout_is_there() -> None:
    expected = {"router", "recorder", "viewer", "dashboard", "opcua"} | {
        f"{role}-{station}" for role in PER_STATION for station in STATIONS
    }
    assert set(SERVICES) == expected
    assert SERVICES["viewer"]["profiles"] == ["viewer"]
    page = build_parser().parse_args(SERVICES["dashboard"]["command"])
    assert page.listen == ("0.0.0.0", 8080) and SERVICES["dashboard"]["ports"] == ["8080:8080"]
    opcua = build_parser().parse_args(SERVICES["opcua"]["command"])
    assert opcua.listen == "opc.tcp://0.0.0.0:4840" and SERVICES["opcua"]["ports"] == ["4840:4840"]
    assert not opcua.anonymous_read_only, "the plant's network reads the line signed and encrypted"
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
    if name in LINE_WIDE:
        assert ids == list(STATIONS), f"the line's {name} serves every station"
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


@pytest.mark.parametrize("reader", ["dashboard", "opcua"])
def test_the_readers_of_the_results_store_read_the_one_the_recorder_writes(reader: str) -> None:
    """The line's page (a part's tightenings) and the OPC UA server (GetResultById, the
    tools of the wear ledger beside it) read the recorder's store: the same stores of the
    same station files, on the same recordings volume, writable (a SQLite reader in WAL
    mode writes the store's shared-memory file)."""
    names = ("recorder", reader)
    stores = {name: stores_of(load_line(station_files(name))) for name in names}
    assert stores[reader] == stores["recorder"]
    for target in stores[reader]:
        assert target.sqlite_path is not None, "the compose line keeps its store in SQLite"
        mounts = {
            name: [
                volume
                for volume in SERVICES[name]["volumes"]
                if target.sqlite_path.is_relative_to(split_volume(volume)[1])
            ]
            for name in names
        }
        assert mounts[reader] == mounts["recorder"] != []
        assert not any(volume.endswith(":ro") for volume in mounts[reader])


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


# -- docker-compose.tls.yml over docker-compose.yml: mutual TLS, one identity per container --

TLS_TEXT = TLS_FILE.read_text()
PREDICTOR_PUTS = {
    channels.EVENTS.topic,
    channels.INTENSITY.topic,
    channels.DECISION.topic,
    channels.STAGE.topic,  # a final stage's commands to the tool
    channels.RUNS.topic,
    channels.RESULTS.topic,  # a run's TighteningResult
    channels.CYCLES.topic,  # a multi-spindle cycle's common result
    channels.PREDICTOR.topic,
}
ROLE_PUTS = {  # what each role publishes (docs/reference/access-control.md), per station
    # the acquisition hosts the station's predictor (placement "edge") and publishes for it,
    # and its spool sends again what the line's recorder lacks (again/<topic>)
    "acquisition": set(channels.topics_of("acquisition")) | PREDICTOR_PUTS | {f"{keys.AGAIN}/**"},
    "predictor": PREDICTOR_PUTS,
    "rig": {channels.PART.topic},  # it stands in for the line's PLC: each part's id
    "recorder": {
        channels.RECORDER.topic,
        channels.QUALITY_ALERT.topic,
        channels.SPOOL_ACK.topic,
        keys.WEAR,
        f"{keys.WEAR}/**",
    },
    "opcua": {channels.ALERT_ACK.topic},  # its clients' acknowledgements of alerts
}
needs_openssl = pytest.mark.skipif(shutil.which("openssl") is None, reason="needs openssl")


def expected_identity(name: str) -> str:
    """The certificate common name a container must present (the ACL's subject)."""
    if name in ("router", "recorder"):
        return {"router": "router", "recorder": "line-recorder"}[name]
    if name == "viewer":
        return "line-viewer"
    if name == "dashboard":  # it only listens: the operator's identity
        return "line-monitor"
    if name == "opcua":  # it puts its clients' acknowledgements of alerts
        return "line-opcua"
    role, station = name.split("-", maxsplit=1)
    return f"{station}-{role}"


class TlsLine:
    """Identities made by the script, and the merged services with their container files."""

    def __init__(self, folder: Path) -> None:
        self.certs = folder / "certs"
        make_compose_certs(self.certs)
        env = {"BOLTWATCH_CERTS": str(self.certs), "BOLTWATCH_RECORDINGS": str(folder / "rec")}
        self.services: dict[str, Any] = load_merged([BASE_FILE, TLS_FILE], env)["services"]
        self.containers = {
            name: ContainerFiles(folder / "containers" / name, service["volumes"])
            for name, service in self.services.items()
        }

    def station_files(self, name: str, command: list[str]) -> list[Path]:
        return [self.containers[name].host(file) for file in config_files(command)]


@pytest.fixture(scope="module")
def tls_line(tmp_path_factory: pytest.TempPathFactory) -> TlsLine:
    if shutil.which("openssl") is None:
        pytest.skip("needs the openssl CLI (config/security/make-compose-certs.sh)")
    return TlsLine(tmp_path_factory.mktemp("compose-tls"))


def test_tls_override_covers_every_service_and_requires_its_variables() -> None:
    override = yaml.safe_load(TLS_TEXT)["services"]
    assert set(override) == set(SERVICES), "every container of the line needs its identity"
    variables = VARIABLE.findall(TLS_TEXT)
    assert variables and all(v.startswith("BOLTWATCH_CERTS:?") for v in variables)
    files = [BASE_FILE, TLS_FILE]
    with pytest.raises(MissingVariableError, match=r"make-compose-certs\.sh"):
        load_merged(files, {"BOLTWATCH_RECORDINGS": "/srv/recordings"})
    with pytest.raises(MissingVariableError, match="BOLTWATCH_RECORDINGS"):
        load_merged(files, {"BOLTWATCH_CERTS": "/srv/certs"})


@pytest.mark.parametrize("name", sorted(SERVICES))
def test_merged_service_keeps_its_mounts_and_adds_its_own_identity(name: str) -> None:
    env = {"BOLTWATCH_CERTS": "/srv/certs", "BOLTWATCH_RECORDINGS": "/srv/recordings"}
    merged = load_merged([BASE_FILE, TLS_FILE], env)["services"][name]
    plain = load_merged([BASE_FILE], env)["services"][name]
    identity = f"/srv/certs/{expected_identity(name)}:{IDENTITY}:ro"
    assert merged["volumes"] == [*plain["volumes"], identity]
    assert merged["healthcheck"] == plain["healthcheck"] | {"test": merged["healthcheck"]["test"]}
    for key in ("depends_on", "ports", "profiles", "network_mode", "image"):
        assert merged.get(key) == plain.get(key), f"{name}: the override changed {key}"


@needs_openssl
@pytest.mark.parametrize("name", sorted(SERVICES))
def test_tls_commands_and_health_checks_run_with_the_containers_identity(
    tls_line: TlsLine, name: str
) -> None:
    service, files = tls_line.services[name], tls_line.containers[name]
    identity = files.host(IDENTITY)
    assert common_name(identity / "identity.pem") == expected_identity(name)
    command = service["command"]
    args = build_parser().parse_args(command)
    assert args.command == "serve" and args.service == served_role(name)
    test = service["healthcheck"]["test"]
    assert test[:2] == ["CMD", "boltwatch"]
    health = build_parser().parse_args(test[2:])
    assert health.command == "health" and health.service == health_role(name)
    checked = tls_line.station_files(name, test[2:])
    if name == "router":
        routed = build_parser().parse_args(files.arguments(command))
        assert routed.listen == ["tls/0.0.0.0:7447"]
        router_config(routed)  # a real zenoh config: TLS files readable, ACL accepted
        assert "DNS:router" in certificate_field(identity / "identity.pem", "-ext subjectAltName")
        acl = json.loads(files.host(f"{IDENTITY}/acl.json5").read_text().split("\n", 1)[1])
        assert acl == line_access_control(list(STATIONS))
    else:
        assert checked == tls_line.station_files(name, command)
        for station in load_line(tls_line.station_files(name, command)):
            assert station.path.parent == files.host("/etc/boltwatch/compose/tls")
    for station in load_line(checked):  # the health check shows this container's certificate
        zenoh_section = station.config.zenoh
        assert zenoh_section.connect == ["tls/router:7447"]
        assert zenoh_section.tls_root_ca == identity / "ca.pem"
        assert zenoh_section.tls_cert == identity / "identity.pem"
        assert zenoh_section.tls_key == identity / "identity.key"


@needs_openssl
@pytest.mark.parametrize("name", sorted(SERVICES))
def test_each_identity_may_put_exactly_what_its_role_publishes(
    tls_line: TlsLine, name: str
) -> None:
    acl = line_access_control(list(STATIONS))
    common = expected_identity(name)
    role = served_role(name)
    if name == "router":
        assert not any(common in s["cert_common_names"] for s in acl["subjects"])
        return
    line_policy = next(p for p in acl["policies"] if p["id"] == "line")
    assert common in line_policy["subjects"], f"{common} may not even declare its health token"
    stations = list(STATIONS) if name in LINE_WIDE else [name.split("-", 1)[1]]
    puts = set() if name == "viewer" else ROLE_PUTS.get(role, set())
    expected = {keys.station_key(st, topic) for st in stations for topic in puts}
    assert put_keys_granted(acl, common) == expected


@needs_openssl
def test_tls_station_files_are_the_plain_ones_with_tls(tls_line: TlsLine) -> None:
    """Apart from [zenoh], config/compose/tls/stationK.toml is config/compose/stationK.toml."""
    files = tls_line.containers["recorder"]
    for station in STATIONS:
        number = station.removeprefix("st")
        plain = station_settings(files.host(f"/etc/boltwatch/compose/station{number}.toml"))
        tls = station_settings(files.host(f"/etc/boltwatch/compose/tls/station{number}.toml"))
        assert tls.pop("zenoh") == plain.pop("zenoh") | {
            "connect": ["tls/router:7447"],
            "tls_root_ca": files.host(f"{IDENTITY}/ca.pem"),
            "tls_cert": files.host(f"{IDENTITY}/identity.pem"),
            "tls_key": files.host(f"{IDENTITY}/identity.key"),
        }
        assert tls == plain


def station_settings(path: Path) -> dict[str, Any]:
    """A station file's settings, its relative paths resolved."""
    settings = load_station(path).config.model_dump()
    for section, key in (("station", "joint"), ("can", "dbc")):
        settings[section][key] = resolve_relative(settings[section][key], path)
    return settings


@needs_openssl
def test_identity_folders_hold_no_ca_key_and_keys_are_private(tls_line: TlsLine) -> None:
    names = {expected_identity(name) for name in SERVICES} | {"line-monitor"}
    made = {p.name for p in tls_line.certs.iterdir()}
    opcua = {"opcua-ca", "opcua-server", "opcua-mes"}  # test_compose_opcua.py checks them
    assert made == names | {"line-ca"} | opcua, "only the identities the compose files use"
    for name in names:
        folder = tls_line.certs / name
        shown = {p.name for p in folder.iterdir()}
        assert shown == {"ca.pem", "identity.pem", "identity.key"} | (
            {"acl.json5"} if name == "router" else set()
        )
        assert stat.S_IMODE((folder / "identity.key").stat().st_mode) == 0o600
    assert (tls_line.certs / "line-ca" / "ca.key").exists()
    assert [p.name for p in (tls_line.certs / "line-ca").glob("*.key")] == ["ca.key"]
    script = CERTS_SCRIPT.read_text()
    uid = re.search(r"--uid (\d+)", (REPO / "Dockerfile").read_text())
    assert uid and f"BOLTWATCH_UID:-{uid.group(1)}" in script, "keys go to the containers' user"
