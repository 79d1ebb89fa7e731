"""``boltwatch serve opcua`` as the system tests run it beside a line: SignAndEncrypt, the
test's certificates, one operator (:data:`USER`), and node-opcua's client subscribed.

- :func:`needs_node_opcua`: node-opcua's folder, or the test skips with the reason (no
  models fetched, no npm);
- :func:`serve_secure_opcua`: the server of the given station files, its users file and
  log in the test's folder;
- :func:`secure_client_options`: the options of ``tests/support/opcua_client.js`` for one of
  the test's client certificates, signed and encrypted, as :data:`USER`;
- :func:`wait_subscribed`: the client's lines until it says it is subscribed (the line may
  start tightening then: no result is missed).
"""

from __future__ import annotations

import subprocess
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pytest

from services.opcua.nodeset_files import missing_files, nodeset_folder
from services.opcua.password_hashes import hash_password
from services.opcua.users_file import OPERATOR, OpcuaUser, write_users
from tests.support.opcua_certificates import OpcuaCertificates, client_uri
from tests.support.opcua_client import node_opcua_client
from tests.support.station_files import serve

USER, PASSWORD = "line-mes", "a password of the line's MES"


def needs_node_opcua() -> Path:
    """node-opcua's modules folder; the test skips where the models or node-opcua are
    missing."""
    if missing_files(nodeset_folder()):
        pytest.skip("the OPC UA models are not fetched (`make opcua-nodesets` needs npm)")
    modules, reason = node_opcua_client()
    if modules is None:
        pytest.skip(reason)
    return modules


def serve_secure_opcua(
    stations: Sequence[Path], endpoint: str, certificates: OpcuaCertificates, folder: Path
) -> tuple[subprocess.Popen[bytes], Path]:
    """The server of ``stations`` on ``endpoint``, :data:`USER` an operator; its log."""
    users = folder / "opcua-users.toml"
    write_users(users, {USER: OpcuaUser(USER, hash_password(PASSWORD), OPERATOR)})
    log = folder / "opcua.log"
    server = serve(
        [
            "opcua",
            "--config",
            *[str(path) for path in stations],
            "--listen",
            endpoint,
            "--certificate",
            str(certificates.server_certificate),
            "--private-key",
            str(certificates.server_key),
            "--trusted-clients",
            str(certificates.trusted_clients),
            "--users",
            str(users),
        ],
        log,
    )
    return server, log


def secure_client_options(
    endpoint: str, certificates: OpcuaCertificates, name: str, stations: Sequence[str], **more: Any
) -> dict[str, Any]:
    """The client ``name``'s options: SignAndEncrypt, :data:`USER`, then ``more``."""
    certificate, key = certificates.clients[name]
    return {
        "endpoint": endpoint,
        "certificate": str(certificate),
        "privateKey": str(key),
        "applicationUri": client_uri(name),
        "security": "SignAndEncrypt",
        "stations": list(stations),
        "userName": USER,
        "password": PASSWORD,
        **more,
    }


def wait_subscribed(client: subprocess.Popen[str], log: Path) -> str:
    """What ``client`` said up to its "subscribed" line (AssertionError with the server's log
    when it ended first)."""
    assert client.stdout is not None
    heard = ""
    while "subscribed" not in heard:
        line = client.stdout.readline()
        assert line, f"the client ended: {heard}\n{log.read_text()}"
        heard += line
    return heard
