"""The compose line's OPC UA server: its RSA files, made by the project's script.

tests/unit/deployment/test_compose.py checks the ``opcua`` service as it checks
every service (command, health check, mounts, dependencies, its TLS identity);
here what is its own. config/security/make-compose-certs.sh makes, with
config/security/make-opcua-certs.sh, the folder ``opcua-server`` that
docker-compose.yml mounts at ``/etc/boltwatch-opcua``: the server starts with
those files (its security options are checked as ``serve opcua`` checks them),
its certificate is RSA and names the application URI and ``opcua``, it trusts
exactly the clients the script's CA signed, its users file holds the script's
client with the password left in the client's folder, and the certificate and
the password stay when the script runs again. The models in the image:
tests/unit/deployment/test_image_models.py.
"""

from __future__ import annotations

import shutil
import stat
import subprocess
from pathlib import Path
from typing import Any

import pytest

from services.cli.main import build_parser
from services.opcua.password_hashes import verify
from services.opcua.server_security import SecuritySettings, application_uri_of
from services.opcua.users_file import read_users
from tests.support.compose_layout import (
    BASE_FILE,
    TLS_FILE,
    ContainerFiles,
    certificate_field,
    load_merged,
    make_compose_certs,
)

OPCUA_FILES = "/etc/boltwatch-opcua"
SERVER_URI = "urn:boltwatch:opcua"
CLIENT = "mes"  # the client the script makes by default (OPCUA_CLIENTS), and its user
USERS = "opcua-users.toml"


@pytest.fixture(scope="module")
def certs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    if shutil.which("openssl") is None:
        pytest.skip("needs the openssl CLI (config/security/make-compose-certs.sh)")
    folder = tmp_path_factory.mktemp("compose-opcua") / "certs"
    make_compose_certs(folder)
    return folder


@pytest.mark.parametrize("files", [[BASE_FILE], [BASE_FILE, TLS_FILE]], ids=["plain", "tls"])
def test_the_server_starts_with_the_files_compose_mounts(
    certs: Path, files: list[Path], tmp_path: Path
) -> None:
    env = {"BOLTWATCH_CERTS": str(certs), "BOLTWATCH_RECORDINGS": str(tmp_path / "rec")}
    service: dict[str, Any] = load_merged(files, env)["services"]["opcua"]
    assert f"{certs}/opcua-server:{OPCUA_FILES}:ro" in service["volumes"]
    container = ContainerFiles(tmp_path / "opcua", service["volumes"])
    args = build_parser().parse_args(container.arguments(service["command"]))
    settings = SecuritySettings(
        args.certificate, args.private_key, args.trusted_clients, args.users
    )
    settings.check()  # what `serve opcua` checks before it starts: files, the users file
    assert args.certificate == container.host(f"{OPCUA_FILES}/server.pem")
    assert application_uri_of(args.certificate) == SERVER_URI  # RSA, URI in its SAN
    names = certificate_field(args.certificate, "-ext subjectAltName")
    assert "DNS:opcua" in names, "the line's containers reach it by its service name"
    key = subprocess.run(
        ["openssl", "pkey", "-in", str(args.private_key), "-pubout"],
        capture_output=True,
        check=True,
    )
    shown = subprocess.run(
        ["openssl", "x509", "-in", str(args.certificate), "-noout", "-pubkey"],
        capture_output=True,
        check=True,
    )
    assert key.stdout == shown.stdout, "the key is the certificate's"


def test_the_server_trusts_the_clients_of_its_ca_only(certs: Path) -> None:
    server = certs / "opcua-server"
    assert {p.relative_to(server).as_posix() for p in server.rglob("*")} == {
        "server.pem",
        "server.key",
        "trusted",
        "trusted/ca.pem",
        "opcua-users.toml",
    }
    client = certs / f"opcua-{CLIENT}"
    shown = {p.name for p in client.iterdir()}
    assert shown == {"identity.pem", "identity.key", "server.pem", "password"}
    for secret in (server / "server.key", server / USERS, client / "identity.key"):
        assert stat.S_IMODE(secret.stat().st_mode) == 0o600, secret
    assert stat.S_IMODE((client / "password").stat().st_mode) == 0o600
    assert (client / "server.pem").read_bytes() == (server / "server.pem").read_bytes()
    uri = certificate_field(client / "identity.pem", "-ext subjectAltName")
    assert f"URI:urn:boltwatch:opcua-client:{CLIENT}" in uri
    trusted = server / "trusted" / "ca.pem"
    verified = subprocess.run(
        [
            "openssl",
            "verify",
            "-CAfile",
            str(trusted),
            "-purpose",
            "sslclient",
            str(client / "identity.pem"),
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert verified.returncode == 0, verified.stdout + verified.stderr
    # The CA key stays in opcua-ca, never mounted; no other key is left there.
    assert [p.name for p in (certs / "opcua-ca").glob("*.key")] == ["ca.key"]


def test_the_users_file_lets_the_scripts_client_in_with_its_password(certs: Path) -> None:
    users = read_users(certs / "opcua-server" / USERS)
    assert set(users) == {CLIENT}
    password = (certs / f"opcua-{CLIENT}" / "password").read_text().removesuffix("\n")
    assert len(password) >= 32, "made by openssl rand, not chosen"
    assert verify(password, users[CLIENT].password_hash)
    assert password not in (certs / "opcua-server" / USERS).read_text()


def test_running_the_script_again_keeps_the_certificate_clients_trust(
    certs: Path, tmp_path: Path
) -> None:
    """A station added (the script run again) must not change the server's certificate
    (an MES trusts that one: it is self-signed) nor a client's password."""
    again = tmp_path / "certs"
    shutil.copytree(certs, again, symlinks=True)
    make_compose_certs(again)
    for name in ("opcua-server/server.pem", "opcua-server/server.key", f"opcua-server/{USERS}"):
        kept = (again / name).read_bytes()
        assert kept == (certs / name).read_bytes(), f"{name} was made again"
    password = f"opcua-{CLIENT}/password"
    assert (again / password).read_bytes() == (certs / password).read_bytes()
    assert [p.name for p in (again / "opcua-ca").glob("*.key")] == ["ca.key"]


def test_a_users_file_made_again_names_every_client_again(certs: Path, tmp_path: Path) -> None:
    """The users file lost, the script run again for two clients: both are in the new file,
    each with the password left in its folder (the kept password of the first one is not
    taken for a user the new file does not have)."""
    again = tmp_path / "certs"
    shutil.copytree(certs, again, symlinks=True)
    make_compose_certs(again, opcua_clients=(CLIENT, "plc"))  # plc: a second client
    (again / "opcua-server" / USERS).unlink()
    make_compose_certs(again, opcua_clients=(CLIENT, "plc"))
    users = read_users(again / "opcua-server" / USERS)
    assert set(users) == {CLIENT, "plc"}
    for name in (CLIENT, "plc"):
        password = (again / f"opcua-{name}" / "password").read_text().removesuffix("\n")
        assert verify(password, users[name].password_hash), name
