"""User names on the OPC UA server: a real asyncua server on loopback, secured as
``boltwatch serve opcua`` secures it (:func:`services.opcua.server_security.apply`), and
real asyncua clients over Basic256Sha256 sign and encrypt with a trusted certificate.

The server holds the standard address space only (no IJT models: who may open a
session does not depend on them), in its own thread and loop, one per module.
"""

from __future__ import annotations

import asyncio
import logging
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from asyncua import Client, Server, ua
from asyncua.crypto.security_policies import SecurityPolicyBasic256Sha256
from asyncua.crypto.uacrypto import CertProperties

from services.opcua.password_hashes import hash_password
from services.opcua.server_security import SecuritySettings, apply
from services.opcua.users_file import OpcuaUser, write_users
from shared.errors import ConfigError
from tests.support.live_recorder import free_port
from tests.support.opcua_certificates import (
    OpcuaCertificates,
    client_uri,
    make_opcua_certificates,
)

USER, PASSWORD = "line-mes", "correct horse battery staple"
CLIENT_TIMEOUT_S = 10.0
START_TIMEOUT_S = 30.0
SERVER_THREAD = "opcua-server"


@pytest.fixture(scope="module")
def certificates(tmp_path_factory: pytest.TempPathFactory) -> OpcuaCertificates:
    return make_opcua_certificates(tmp_path_factory.mktemp("pki"), untrusted=("stranger",))


@pytest.fixture(scope="module")
def users_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("users") / "opcua-users.toml"
    write_users(path, {USER: OpcuaUser(USER, hash_password(PASSWORD))})
    return path


@contextmanager
def serving(settings: SecuritySettings) -> Iterator[str]:
    """The server's endpoint while it runs (in a thread of its own)."""
    endpoint = f"opc.tcp://127.0.0.1:{free_port()}"
    started, stop = threading.Event(), threading.Event()
    failed: list[BaseException] = []

    async def serve() -> None:
        server = Server()
        await server.init()
        server.set_endpoint(endpoint)
        await apply(server, settings)
        async with server:
            started.set()
            while not stop.is_set():
                await asyncio.sleep(0.02)

    def work() -> None:
        try:
            asyncio.run(serve())
        except BaseException as err:  # given to the test
            failed.append(err)
            started.set()

    thread = threading.Thread(target=work, name=SERVER_THREAD)
    thread.start()
    try:
        assert started.wait(START_TIMEOUT_S), "the server did not start"
        if failed:
            raise failed[0]
        yield endpoint
    finally:
        stop.set()
        thread.join()


@pytest.fixture(scope="module")
def users_required(certificates: OpcuaCertificates, users_file: Path) -> Iterator[str]:
    """The default: certificates, trusted clients and users."""
    settings = SecuritySettings(
        certificate=certificates.server_certificate,
        private_key=certificates.server_key,
        trusted_clients=certificates.trusted_clients,
        users=users_file,
    )
    with serving(settings) as endpoint:
        yield endpoint


def _session_state(
    endpoint: str,
    certificates: OpcuaCertificates,
    user: str | None,
    password: str | None,
    name: str = "client",
) -> int:
    """The server's ServerStatus/State (0: running) read in a session of ``user``, the client
    ``name`` of ``certificates``."""

    async def read() -> int:
        client = Client(endpoint, timeout=CLIENT_TIMEOUT_S)
        client.application_uri = client_uri(name)
        certificate, key = certificates.clients[name]
        await client.set_security(
            SecurityPolicyBasic256Sha256,
            certificate=str(certificate),
            private_key=CertProperties(key, extension="pem"),
            mode=ua.MessageSecurityMode.SignAndEncrypt,
        )
        if user is not None:
            client.set_user(user)
        if password is not None:
            client.set_password(password)
        async with client:
            node = client.get_node(ua.ObjectIds.Server_ServerStatus_State)
            return int(await node.read_value())

    return asyncio.run(read())


def test_a_user_with_the_right_password_gets_a_session_and_reads(
    users_required: str, certificates: OpcuaCertificates
) -> None:
    assert _session_state(users_required, certificates, USER, PASSWORD) == ua.ServerState.Running


@pytest.mark.parametrize(
    ("user", "password"),
    [(USER, "wrong"), (USER, ""), ("nobody", PASSWORD)],
    ids=["wrong password", "empty password", "unknown user"],
)
def test_a_wrong_password_or_an_unknown_user_is_refused(
    users_required: str, certificates: OpcuaCertificates, user: str, password: str
) -> None:
    with pytest.raises(ua.uaerrors.BadUserAccessDenied):
        _session_state(users_required, certificates, user, password)


def test_a_session_without_a_user_is_refused_and_only_user_names_are_offered(
    users_required: str, certificates: OpcuaCertificates
) -> None:
    with pytest.raises(ua.uaerrors.BadIdentityTokenRejected):
        _session_state(users_required, certificates, None, None)

    async def endpoints() -> list[ua.EndpointDescription]:
        return list(
            await Client(
                users_required, timeout=CLIENT_TIMEOUT_S
            ).connect_and_get_server_endpoints()
        )

    offered = asyncio.run(endpoints())
    assert [e.SecurityMode for e in offered] == [ua.MessageSecurityMode.SignAndEncrypt]
    assert [t.TokenType for t in offered[0].UserIdentityTokens] == [ua.UserTokenType.UserName]


def test_anonymous_read_only_with_users_is_refused_at_start(
    certificates: OpcuaCertificates, users_file: Path
) -> None:
    """asyncua would offer the UserName token on the None endpoint too and take its
    password in clear."""
    settings = SecuritySettings(
        certificate=certificates.server_certificate,
        private_key=certificates.server_key,
        trusted_clients=certificates.trusted_clients,
        users=users_file,
        anonymous_read_only=True,
    )
    with pytest.raises(ConfigError, match="give --users or --anonymous-read-only, not both"):
        asyncio.run(apply(Server(), settings))  # refused before the server is touched


def test_a_users_file_anyone_on_the_host_may_read_is_warned_of(
    certificates: OpcuaCertificates,
    users_file: Path,
    tmp_path: Path,
    caplog: pytest.LogCaptureFixture,
) -> None:
    readable = tmp_path / "opcua-users.toml"
    readable.write_bytes(users_file.read_bytes())
    readable.chmod(0o644)
    settings = SecuritySettings(
        certificate=certificates.server_certificate,
        private_key=certificates.server_key,
        trusted_clients=certificates.trusted_clients,
        users=readable,
    )

    async def secure() -> None:
        server = Server()
        await server.init()
        await apply(server, settings)

    with caplog.at_level(logging.WARNING, "services.opcua"):
        asyncio.run(secure())
    assert f"--users {readable}: anyone on this host may read it" in caplog.text


@pytest.mark.parametrize(
    ("name", "user", "password", "refused", "said"),
    [
        ("stranger", USER, PASSWORD, ua.uaerrors.BadCertificateUntrusted, "--trusted-clients"),
        ("client", USER, "wrong", ua.uaerrors.BadUserAccessDenied, f"user {USER!r} refused"),
        ("client", "nobody", PASSWORD, ua.uaerrors.BadUserAccessDenied, "user 'nobody' refused"),
        ("client", None, None, ua.uaerrors.BadIdentityTokenRejected, "anonymous"),
    ],
    ids=["untrusted certificate", "wrong password", "unknown user", "anonymous"],
)
def test_a_refused_session_leaves_one_line_in_the_log(
    users_required: str,
    certificates: OpcuaCertificates,
    caplog: pytest.LogCaptureFixture,
    name: str,
    user: str | None,
    password: str | None,
    refused: type[Exception],
    said: str,
) -> None:
    """What the server's thread logs at WARNING and above (the service's asyncua level) for
    one refused session: one line, without a traceback, saying why."""
    with caplog.at_level(logging.WARNING), pytest.raises(refused):
        _session_state(users_required, certificates, user, password, name)
    lines = [record for record in caplog.records if record.threadName == SERVER_THREAD]
    assert len(lines) == 1, [record.getMessage() for record in lines]
    [line] = lines
    assert line.exc_info is None and line.exc_text is None
    assert said in line.getMessage() and "\n" not in line.getMessage()
