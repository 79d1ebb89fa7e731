"""The [zenoh] section's reconnect and TLS keys, and RouterLink on real loopback sessions."""

from __future__ import annotations

import threading
import time
from pathlib import Path

import pytest
import zenoh
from pydantic import ValidationError

from shared.config import ZenohSection
from shared.errors import TransportError
from shared.runtime import RouterLink, open_session, zenoh_config
from tests.support.station_files import free_tcp_port


def section(data: dict[str, object], source: Path | None = None) -> ZenohSection:
    context = {"source": source} if source is not None else None
    return ZenohSection.model_validate(data, context=context)


def test_tls_paths_are_relative_to_the_station_file(tmp_path: Path) -> None:
    for name in ("ca.pem", "me.pem", "me.key"):
        (tmp_path / name).write_text("x")
    got = section(
        {
            "connect": ["tls/127.0.0.1:7447"],
            "tls_root_ca": "ca.pem",
            "tls_cert": "me.pem",
            "tls_key": "me.key",
        },
        tmp_path / "station.toml",
    )
    assert got.tls_root_ca == tmp_path / "ca.pem" and got.tls_key == tmp_path / "me.key"


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"tls_root_ca": "missing.pem"}, "cannot read"),
        ({"tls_root_ca": "ca.pem", "tls_cert": "ca.pem"}, "tls_cert and tls_key together"),
        ({}, "tls/ endpoints need tls_root_ca"),
        ({"connect": ["tcp/127.0.0.1:7447"], "tls_root_ca": "ca.pem"}, "no endpoint is tls/"),
        ({"reconnect_period_max_s": 0}, "greater than 0"),
    ],
)
def test_bad_tls_and_reconnect_keys_say_what_is_wrong(
    tmp_path: Path, data: dict[str, object], message: str
) -> None:
    (tmp_path / "ca.pem").write_text("x")
    with pytest.raises(ValidationError, match=message):
        section({"connect": ["tls/127.0.0.1:7447"], **data}, tmp_path / "station.toml")


def test_a_client_with_a_timeout_fails_clearly_without_a_router() -> None:
    endpoint = f"tcp/127.0.0.1:{free_tcp_port()}"
    with pytest.raises(TransportError, match=rf"no zenoh router at {endpoint} within"):
        open_session(section({"connect": [endpoint], "connect_timeout_s": 0.3}))


def test_router_link_follows_the_transport_down_and_up() -> None:
    endpoint = f"tcp/127.0.0.1:{free_tcp_port()}"
    changes: list[tuple[bool, float]] = []
    changed = threading.Event()

    def on_change(connected: bool, outage_s: float) -> None:
        changes.append((connected, outage_s))
        changed.set()

    router = zenoh.open(zenoh_config("router", listen=[endpoint]))
    client = zenoh.open(zenoh_config("client", [endpoint], reconnect_period_max_ms=200))
    link = RouterLink(client, on_change)
    try:
        assert link.connected
        router.close()
        assert changed.wait(10.0) and changes == [(False, 0.0)] and not link.connected
        changed.clear()
        time.sleep(0.2)
        router = zenoh.open(zenoh_config("router", listen=[endpoint]))
        assert changed.wait(10.0) and link.connected
        assert changes[-1][0] and changes[-1][1] >= 0.2
    finally:
        link.close()
        client.close()
        router.close()


def test_a_spooling_service_opens_without_its_router_and_reaches_it_later() -> None:
    """A client that must not wait (its spool keeps what it measures) opens at once, reaches
    the router when it comes, and is then on the line both ways, as a client is."""
    endpoint = f"tcp/127.0.0.1:{free_tcp_port()}"
    zenoh_section = section({"connect": [endpoint], "reconnect_period_max_s": 0.2})
    station = open_session(zenoh_section, wait_for_router=False)
    router = zenoh.open(zenoh_config("router", listen=[endpoint]))
    other = zenoh.open(zenoh_config("client", [endpoint]))
    heard: list[bytes] = []
    told: list[bytes] = []
    try:
        link = RouterLink(station, lambda connected, outage_s: None)
        deadline = time.monotonic() + 10
        while not link.connected and time.monotonic() < deadline:
            time.sleep(0.05)
        assert link.connected
        station.declare_subscriber("t/ack", lambda s: told.append(s.payload.to_bytes()))
        other.declare_subscriber("t/data", lambda s: heard.append(s.payload.to_bytes()))
        deadline = time.monotonic() + 10
        while (not heard or not told) and time.monotonic() < deadline:
            station.put("t/data", b"measured")
            other.put("t/ack", b"filed")
            time.sleep(0.1)
        assert heard and told
        link.close()
    finally:
        station.close()
        other.close()
        router.close()
