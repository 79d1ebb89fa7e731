"""The compose line's OPC UA server run on loopback with the files compose mounts.

The router and ``opcua`` of docker-compose.yml with docker-compose.tls.yml run
their merged commands (tests/support/compose_line.py), with the identities and
the OPC UA server's RSA files config/security/make-compose-certs.sh made:
compose's health check passes (the server holds its token for both stations
under line-opcua's certificate, which the router's access control lets
listen), and an asyncua client with the script's client identity
(``opcua-mes``) connects with Basic256Sha256 sign and encrypt, trusting the
server's certificate from its folder, logs in as the script's user ``mes``
with the password left in that folder, and finds both stations' joining systems.
About 10 s (the seven models load in the server).
"""

from __future__ import annotations

import asyncio
import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest
from asyncua import Client, ua
from asyncua.crypto.security_policies import SecurityPolicyBasic256Sha256
from asyncua.crypto.uacrypto import CertProperties

from services.opcua.joining_systems import BOLTWATCH_NAMESPACE
from services.opcua.nodeset_files import missing_files, nodeset_folder
from tests.support.compose_line import ComposeLine, running_line

pytestmark = [
    pytest.mark.system,
    pytest.mark.skipif(shutil.which("openssl") is None, reason="needs the openssl CLI"),
]

RUNNING = ("router", "opcua")
STATIONS = ["st1", "st2"]
CLIENT = "mes"  # make-compose-certs.sh's default OPC UA client
HEALTHY_WITHIN_S = 90.0  # the models load before the server reaches the line
CLIENT_TIMEOUT_S = 30.0


@pytest.fixture
def line(tmp_path: Path) -> Iterator[ComposeLine]:
    if missing_files(nodeset_folder()):
        pytest.skip("the OPC UA models are not fetched (`make opcua-nodesets` needs npm)")
    with running_line(tmp_path, RUNNING) as started:
        yield started


async def joining_systems(line: ComposeLine) -> list[str]:
    """The stations' joining systems an MES with the script's client identity and user
    finds."""
    identity = line.certs / f"opcua-{CLIENT}"
    client = Client(f"opc.tcp://127.0.0.1:{line.opcua_port}", timeout=CLIENT_TIMEOUT_S)
    client.application_uri = f"urn:boltwatch:opcua-client:{CLIENT}"
    client.set_user(CLIENT)
    client.set_password((identity / "password").read_text().removesuffix("\n"))
    await client.set_security(
        SecurityPolicyBasic256Sha256,
        certificate=str(identity / "identity.pem"),
        # asyncua takes a file's format from its name: ".key" is PEM here
        private_key=CertProperties(identity / "identity.key", extension="pem"),
        server_certificate=str(identity / "server.pem"),
        mode=ua.MessageSecurityMode.SignAndEncrypt,
    )
    async with client:
        ours = await client.get_namespace_index(BOLTWATCH_NAMESPACE)
        names: list[str] = []
        for station in STATIONS:
            name = await client.get_node(f"ns={ours};s={station}").read_browse_name()
            names.append(str(name.Name))
        return names


def test_the_opcua_service_serves_both_stations_with_the_scripts_files(
    line: ComposeLine,
) -> None:
    line.wait_healthy(RUNNING, HEALTHY_WITHIN_S)
    assert asyncio.run(joining_systems(line)) == STATIONS, line.log("opcua")
