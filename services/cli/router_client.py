"""A short-lived client of the line's router for the operator's commands (status, wear --plant).

``--connect ENDPOINT`` (plain tcp) or the router of a station file's
``[zenoh] connect``, reached the way that file's services reach it (its
``tls_*`` files: with mutual TLS, e.g. a ``line-monitor`` certificate).
Opening it is a TransportError naming the endpoint when no router answers.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import zenoh

CONNECT_TIMEOUT_MS = 2000


def router_client(config: Path, connect: str | None) -> tuple[str, zenoh.Config]:
    """The router endpoint and a client config that reaches it (``connect`` wins)."""
    from shared.runtime import zenoh_config

    if connect is not None:
        return connect, zenoh_config("client", [connect], connect_timeout_ms=CONNECT_TIMEOUT_MS)
    return _router_of(config)


def _router_of(config: Path) -> tuple[str, zenoh.Config]:
    from shared.config import load_any_station
    from shared.errors import ConfigError
    from shared.runtime import client_config

    section = load_any_station(config).config.zenoh
    if not section.connect:
        raise ConfigError(
            f"{config}: zenoh.connect is empty (a peer that only listens); "
            "give the router with --connect ENDPOINT"
        )
    endpoint = section.connect[0]
    return endpoint, client_config(section, CONNECT_TIMEOUT_MS, [endpoint])


def open_client(endpoint: str, config: zenoh.Config) -> zenoh.Session:
    """The session; TransportError naming ``endpoint`` when its router does not answer."""
    import zenoh

    from shared.errors import TransportError
    from shared.runtime import zenoh_reason

    try:
        return zenoh.open(config)
    except zenoh.ZError as err:
        raise TransportError(
            f"cannot reach the zenoh router at {endpoint} within "
            f"{CONNECT_TIMEOUT_MS / 1000:.0f} s ({zenoh_reason(err)}); is 'boltwatch serve "
            "router' running there?"
        ) from err
