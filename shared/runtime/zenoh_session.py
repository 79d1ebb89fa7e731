"""Open zenoh sessions from station configuration, and watch the link to the router.

Multicast scouting is always off: every session names its endpoints, so a
station joins exactly the line it is configured for.

Reconnection (verified against zenoh 1.10, tests/system/test_router_restart.py):
a client whose router goes away keeps its publishers and subscribers and
retries ``connect/endpoints`` with a growing pause (``connect/retry``:
``period_init_ms`` doubling up to ``period_max_ms``), for ever; when the router
is back the session re-declares everything by itself. What is published in
between has nowhere to go and is lost: :class:`RouterLink` tells the
publisher so that it can count it. At open, a client waits
``connect/timeout_ms`` for its router (-1: for ever) and fails otherwise.

A service that keeps what it measures in a spool (``[spool]``, store and
forward) must not wait: an acquisition restarted while its cable is out
would miss every run until the cable is back. A zenoh client cannot open
without its router, so such a service opens as a peer that connects to the
same endpoints and to nothing else (gossip off, listening nowhere): it opens
at once, reaches its router in the background, and is on the line as a
client is (``open_session(..., wait_for_router=False)``).
"""

from __future__ import annotations

import json
import logging
import re
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import zenoh

from shared.config import ENDPOINT_EXPECTED, ZenohSection
from shared.contract import Channel
from shared.errors import ConfigError, TransportError

LOG = logging.getLogger(__name__)

RECONNECT_PERIOD_INIT_MS = 250
RECONNECT_PERIOD_MAX_MS = 2000


@dataclass(frozen=True, slots=True)
class TlsFiles:
    """PEM files of one zenoh node: the line's CA, and its own certificate and key (mTLS)."""

    root_ca: Path
    cert: Path | None = None
    key: Path | None = None


def zenoh_config(
    mode: str,
    connect: Sequence[str] = (),
    listen: Sequence[str] = (),
    connect_timeout_ms: int = -1,
    reconnect_period_max_ms: int = RECONNECT_PERIOD_MAX_MS,
    tls: TlsFiles | None = None,
    connect_only: bool = False,
    lease_ms: int | None = None,
) -> zenoh.Config:
    """A zenoh.Config with ``mode``, endpoints, and multicast scouting off.

    ``connect_only``: a peer that reaches the line only through ``connect``
    (gossip off: it learns of no other peer to connect to). ``lease_ms``: how
    long the others keep this session once it goes silent (zenoh's
    ``transport/link/tx/lease``; None: zenoh's default, 10 s).

    A client waits ``connect_timeout_ms`` for its router at open (-1: for ever,
    so services may start before the router and survive its late start), and
    after losing it retries for ever, at most ``reconnect_period_max_ms`` apart.
    """
    config = zenoh.Config()
    config.insert_json5("mode", json.dumps(mode))
    config.insert_json5("scouting/multicast/enabled", "false")
    _insert_endpoints(config, "connect/endpoints", connect)
    _insert_endpoints(config, "listen/endpoints", listen)
    retry = {
        "period_init_ms": min(RECONNECT_PERIOD_INIT_MS, reconnect_period_max_ms),
        "period_max_ms": reconnect_period_max_ms,
        "period_increase_factor": 2,
    }
    config.insert_json5("connect/retry", json.dumps(retry))
    if mode == "client":
        config.insert_json5("connect/timeout_ms", json.dumps(connect_timeout_ms))
    if connect_only:
        config.insert_json5("scouting/gossip/enabled", "false")
    if lease_ms is not None:
        config.insert_json5("transport/link/tx/lease", json.dumps(lease_ms))
    if tls is not None:
        _insert_tls(config, tls)
    return config


def _insert_endpoints(config: zenoh.Config, key: str, endpoints: Sequence[str]) -> None:
    """Endpoints zenoh cannot parse (``--connect notanendpoint``) are a ConfigError naming
    the endpoint."""
    for endpoint in endpoints:
        try:
            zenoh.Config().insert_json5(key, json.dumps([endpoint]))
        except zenoh.ZError as err:
            raise ConfigError(f"zenoh endpoint {endpoint!r}: {ENDPOINT_EXPECTED}") from err
    config.insert_json5(key, json.dumps(list(endpoints)))


def zenoh_reason(err: zenoh.ZError) -> str:
    """A zenoh error's message without the Rust source locations (`` at /root/.cargo/...``)."""
    text = str(err)
    match = re.search(r'msg: "(.*?)(?: at /\S+)?"', text)  # Json5Err(Message { msg: "..." })
    if match:
        text = match.group(1)
    text = re.sub(r"\s+at /\S+\.rs:\d+\.?", "", text)
    # a JSON5 parse error drawn over several lines: "--> 1:1\n |\n1 | x\n | ^---\n = expected ..."
    drawn = re.search(r"--> (\d+):(\d+).*= (.+)$", text)
    if drawn:
        text = f"line {drawn[1]}, column {drawn[2]}: {drawn[3]}"
    return " ".join(text.replace("\\n", " ").split())


def _insert_tls(config: zenoh.Config, tls: TlsFiles) -> None:
    """The same certificate serves both ways: a router listens, a client connects."""
    link = {"root_ca_certificate": str(tls.root_ca)}
    if tls.cert is not None and tls.key is not None:
        link |= {
            "listen_certificate": str(tls.cert),
            "listen_private_key": str(tls.key),
            "connect_certificate": str(tls.cert),
            "connect_private_key": str(tls.key),
        }
    config.insert_json5("transport/link/tls", json.dumps(link))
    # Mutual TLS: every side must show a certificate signed by the line's CA.
    config.insert_json5("transport/link/tls/enable_mtls", json.dumps(tls.cert is not None))


def section_config(section: ZenohSection, wait_for_router: bool = True) -> zenoh.Config:
    """The zenoh.Config of a station's ``[zenoh]`` section (``wait_for_router`` False: a
    client opens as a peer connected to its router only, at once)."""
    timeout_ms = -1 if section.connect_timeout_s is None else round(section.connect_timeout_s * 1e3)
    alone = section.mode == "client" and not wait_for_router
    return zenoh_config(
        "peer" if alone else section.mode,
        section.connect,
        section.listen,
        connect_timeout_ms=timeout_ms,
        reconnect_period_max_ms=round(section.reconnect_period_max_s * 1e3),
        tls=_tls_files(section),
        connect_only=alone,
        lease_ms=round(section.lease_s * 1e3),
    )


def _tls_files(section: ZenohSection) -> TlsFiles | None:
    if section.tls_root_ca is None:
        return None
    return TlsFiles(section.tls_root_ca, section.tls_cert, section.tls_key)


def client_config(
    section: ZenohSection, connect_timeout_ms: int, connect: Sequence[str] | None = None
) -> zenoh.Config:
    """A short-lived client (``health``, ``status``) that reaches the router the way the
    section's services do: its endpoints (or ``connect``) and its TLS files, so with
    mutual TLS it shows the section's certificate."""
    endpoints = section.connect if connect is None else connect
    return zenoh_config(
        "client", endpoints, connect_timeout_ms=connect_timeout_ms, tls=_tls_files(section)
    )


def open_session(section: ZenohSection, wait_for_router: bool = True) -> zenoh.Session:
    """Open a session for a station service; errors name the endpoints tried.
    ``wait_for_router`` False: a client does not wait for its router (a spooling service)."""
    where = ", ".join(section.connect) or "(no connect endpoints)"
    if section.mode == "client" and not wait_for_router:
        LOG.info(
            "reaching the zenoh router at %s in the background (the spool keeps "
            "what is measured meanwhile)",
            where,
        )
        return open_from(section_config(section, wait_for_router=False))
    if section.mode == "client":
        waiting = (
            "for ever"
            if section.connect_timeout_s is None
            else f"up to {section.connect_timeout_s:g} s"
        )
        LOG.info("connecting to zenoh router at %s (waiting %s)", where, waiting)
    try:
        return open_from(section_config(section))
    except TransportError as err:
        if section.mode == "client" and section.connect_timeout_s is not None:
            raise TransportError(
                f"no zenoh router at {where} within zenoh.connect_timeout_s = "
                f"{section.connect_timeout_s:g} s (is `boltwatch serve router` running "
                f"there?): {err}"
            ) from err
        raise


def open_from(config: zenoh.Config) -> zenoh.Session:
    try:
        session = zenoh.open(config)
    except zenoh.ZError as err:
        raise TransportError(f"cannot open zenoh session: {zenoh_reason(err)}") from err
    LOG.info("zenoh session %s open", session.zid())
    return session


class RouterLink:
    """Whether the session can reach anyone (its router, or a peer), kept by zenoh's events.

    ``connected`` is a plain attribute, so the 1 kHz sample path reads it for
    the price of an attribute lookup; zenoh's transport-events callback sets
    it when a transport opens or closes. ``on_change(connected, outage_s)``
    is called from that callback (``outage_s``: how long the link was down,
    0 when it goes down). Close it before the session.
    """

    def __init__(
        self,
        session: zenoh.Session,
        on_change: Callable[[bool, float], None] | None = None,
        clock_s: Callable[[], float] = time.monotonic,
    ) -> None:
        self._on_change = on_change
        self._clock_s = clock_s
        self._lock = threading.Lock()
        self._remotes = {str(t.zid) for t in session.info.transports()}
        self.connected = bool(self._remotes)
        self._lost_at_s: float | None = None if self.connected else clock_s()
        self._listener = session.info.declare_transport_events_listener(self._on_event)

    def _on_event(self, event: zenoh.TransportEvent) -> None:
        with self._lock:
            zid = str(event.transport.zid)
            if event.kind == zenoh.SampleKind.PUT:
                self._remotes.add(zid)
            else:
                self._remotes.discard(zid)
            connected = bool(self._remotes)
            if connected == self.connected:
                return
            self.connected = connected
            outage_s = 0.0
            if connected:
                lost_at = self._lost_at_s
                outage_s = 0.0 if lost_at is None else self._clock_s() - lost_at
                self._lost_at_s = None
            else:
                self._lost_at_s = self._clock_s()
        if self._on_change is not None:
            self._on_change(connected, outage_s)

    def close(self) -> None:
        self._listener.undeclare()


def declare_channel(session: zenoh.Session, channel: Channel[Any], station: str) -> zenoh.Publisher:
    """A publisher of ``channel`` for ``station``, with the channel's options (its Qos)."""
    qos = channel.qos
    return session.declare_publisher(
        channel.key(station),
        priority=zenoh.Priority.REAL_TIME if qos.real_time else zenoh.Priority.DATA,
        express=qos.express,
        congestion_control=zenoh.CongestionControl.BLOCK,
    )
