"""A router with mutual TLS and access control: only st1's own services may decide for st1.

Certificates are made by the documented script (config/security/make-certs.sh,
the ``openssl`` CLI) into the test's folder; the router runs as
``boltwatch serve router`` with ``--tls-*`` and the access control that
services/router/access_control.py writes for st1 and st2. Sessions are opened the
way services open them: from a ``[zenoh]`` section with ``tls_*`` keys.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
import zenoh

from services.cli.station_supervisor import stop_process
from services.router.access_control import line_access_control
from shared.config import ZenohSection
from shared.contract import channels
from shared.errors import TransportError
from shared.runtime import open_session
from tests.support.live_recorder import has_subscribers
from tests.support.paths import REPO
from tests.support.station_files import free_tcp_port

pytestmark = [
    pytest.mark.system,
    pytest.mark.skipif(shutil.which("openssl") is None, reason="needs the openssl CLI"),
]

DECISION = channels.DECISION.key("st1")
OTHER_DECISION = channels.DECISION.key("st2")
NAMES = ("st1-predictor", "st1-acquisition", "st2-acquisition", "line-recorder", "rogue")
OPEN_TIMEOUT_S = 20.0
REFUSED_TIMEOUT_S = 2.0


class SecureLine:
    def __init__(self, folder: Path) -> None:
        self.certs = folder / "certs"
        script = REPO / "config" / "security" / "make-certs.sh"
        subprocess.run([str(script), str(self.certs), *NAMES], check=True, capture_output=True)
        acl = folder / "access_control.json5"
        acl.write_text(json.dumps(line_access_control(["st1", "st2"])))
        self.port = free_tcp_port()
        self.endpoint = f"tls/127.0.0.1:{self.port}"
        tls = [f"--tls-{k}={self.certs / v}" for k, v in self._router_files().items()]
        with (folder / "router.log").open("wb") as log:
            serve = [sys.executable, "-m", "services.cli", "serve", "router"]
            self.router = subprocess.Popen(
                [*serve, "--listen", self.endpoint, *tls, "--access-control", str(acl)],
                cwd=REPO,
                stdout=log,
                stderr=subprocess.STDOUT,
            )

    @staticmethod
    def _router_files() -> dict[str, str]:
        return {"root-ca": "ca.pem", "cert": "router.pem", "key": "router.key"}

    def section(
        self, name: str | None, timeout_s: float = OPEN_TIMEOUT_S, endpoint: str | None = None
    ) -> ZenohSection:
        """A [zenoh] section as a station file would give it (paths relative to the file)."""
        data: dict[str, object] = {
            "connect": [endpoint or self.endpoint],
            "connect_timeout_s": timeout_s,
        }
        if (endpoint or self.endpoint).startswith("tls/"):
            data["tls_root_ca"] = "certs/ca.pem"
            if name is not None:
                data |= {"tls_cert": f"certs/{name}.pem", "tls_key": f"certs/{name}.key"}
        station_file = self.certs.parent / "station.toml"
        return ZenohSection.model_validate(data, context={"source": station_file})


@pytest.fixture
def line(tmp_path: Path) -> Iterator[SecureLine]:
    started = SecureLine(tmp_path)
    try:
        yield started
    finally:
        stop_process(started.router, grace_s=10.0)


def test_only_the_stations_acquisition_and_predictor_may_put_its_decision(
    line: SecureLine,
) -> None:
    """st1-acquisition (its edge predictor) and st1-predictor (a line predictor) decide for
    st1; an unknown name and st2's acquisition do not."""
    heard: dict[str, list[bytes]] = {}
    arrived = threading.Condition()

    def on_decision(sample: zenoh.Sample) -> None:
        with arrived:
            heard.setdefault(str(sample.key_expr), []).append(sample.payload.to_bytes())
            arrived.notify_all()

    sessions = []
    try:
        monitor = open_session(line.section("line-recorder"))
        sessions.append(monitor)
        subscriber = monitor.declare_subscriber(channels.DECISION.key("*"), on_decision)
        for name in ("rogue", "st2-acquisition", "st1-acquisition", "st1-predictor"):
            sessions.append(open_session(line.section(name)))
        rogue, other_station, acquisition, predictor = sessions[1:]
        # Everyone's connected: the router's subscriber declaration reached the publishers.
        publishers = [s.declare_publisher(DECISION) for s in (acquisition, predictor)]
        own = other_station.declare_publisher(OTHER_DECISION)  # what st2's acquisition may put
        deadline = time.monotonic() + OPEN_TIMEOUT_S
        while not all(has_subscribers(p) for p in (*publishers, own)):
            assert time.monotonic() < deadline, "no subscriber matched the decisions"
            time.sleep(0.05)
        # The impostors first: if the router let them through they would arrive first.
        rogue.put(DECISION, b"rogue")
        other_station.put(DECISION, b"st2-acquisition")
        own.put(b"st2-own")  # after it on the same link: heard, so the one before was handled
        for publisher, said in zip(publishers, (b"acquisition", b"predictor"), strict=True):
            publisher.put(said)
        with arrived:
            assert arrived.wait_for(
                lambda: len(heard.get(DECISION, [])) >= 2 and OTHER_DECISION in heard,
                timeout=10.0,
            ), f"the legitimate decisions never arrived (heard {heard})"
        time.sleep(0.3)  # anything else in flight (the rogue's own link) lands now
        assert sorted(heard[DECISION]) == [b"acquisition", b"predictor"]
        assert heard[OTHER_DECISION] == [b"st2-own"]
        for publisher in (*publishers, own):
            publisher.undeclare()
        subscriber.undeclare()
    finally:
        for session in sessions:
            session.close()


def test_a_stations_services_may_ask_the_lines_recorder_for_its_part(line: SecureLine) -> None:
    """A predictor that starts asks the line for the part at its station
    (``boltwatch/<st>/part``): st1-acquisition (its edge predictor) and st1-predictor (a line
    predictor) query, line-recorder answers, through the access control."""
    part = channels.PART.key("st1")
    sessions = []
    try:
        recorder = open_session(line.section("line-recorder"))
        sessions.append(recorder)

        def answer(query: zenoh.Query) -> None:
            with query:
                query.reply(part, b'{"station": "st1", "part_id": "WHEEL-A", "time_ns": 1}')

        queryable = recorder.declare_queryable(part, answer)
        for name in ("st1-acquisition", "st1-predictor"):
            asking = open_session(line.section(name))
            sessions.append(asking)
            answered: list[bytes] = []
            deadline = time.monotonic() + OPEN_TIMEOUT_S
            while not answered:  # until the queryable's declaration reached the router
                assert time.monotonic() < deadline, f"{name}: the line never answered"
                answered = [
                    reply.ok.payload.to_bytes()
                    for reply in asking.get(part, timeout=2.0)
                    if reply.ok is not None
                ]
                if not answered:
                    time.sleep(0.1)
            assert b"WHEEL-A" in answered[0], name
        queryable.undeclare()
    finally:
        for session in sessions:
            session.close()


def test_a_session_without_client_certificate_is_rejected(line: SecureLine) -> None:
    _wait_for_router(line)
    started = time.monotonic()
    with pytest.raises(TransportError, match="connect_timeout_s"):
        open_session(line.section(None, timeout_s=REFUSED_TIMEOUT_S)).close()
    assert time.monotonic() - started < REFUSED_TIMEOUT_S + 5.0


def test_plain_tcp_cannot_reach_a_tls_only_router(line: SecureLine) -> None:
    _wait_for_router(line)
    plain = f"tcp/127.0.0.1:{line.port}"
    with pytest.raises(TransportError, match="no zenoh router at tcp/"):
        open_session(line.section(None, timeout_s=REFUSED_TIMEOUT_S, endpoint=plain)).close()


def _wait_for_router(line: SecureLine) -> None:
    """The router is up (a legitimate session gets in), so a refusal is a refusal."""
    open_session(line.section("line-recorder")).close()
