"""Open zenoh sessions from station configuration.

Multicast scouting is always off: every session names its endpoints, so a
station joins exactly the line it is configured for.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Sequence

import zenoh

from shared.config.station import ZenohSection
from shared.errors import TransportError

LOG = logging.getLogger(__name__)


def zenoh_config(
    mode: str,
    connect: Sequence[str] = (),
    listen: Sequence[str] = (),
    connect_timeout_ms: int = -1,
) -> zenoh.Config:
    """A zenoh.Config with ``mode``, endpoints, and multicast scouting off.

    A client waits ``connect_timeout_ms`` for its router at open (-1: for ever,
    so services may start before the router and survive its late start).
    """
    config = zenoh.Config()
    config.insert_json5("mode", json.dumps(mode))
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("connect/endpoints", json.dumps(list(connect)))
    config.insert_json5("listen/endpoints", json.dumps(list(listen)))
    if mode == "client":
        # Keep trying to reach the router for ever: it may start later or restart.
        config.insert_json5("connect/timeout_ms", json.dumps(connect_timeout_ms))
    return config


def open_session(section: ZenohSection) -> zenoh.Session:
    """Open a session for a station service; errors name the endpoints tried."""
    if section.mode == "client":
        LOG.info("connecting to zenoh router at %s", ", ".join(section.connect))
    return open_from(zenoh_config(section.mode, section.connect, section.listen))


def open_from(config: zenoh.Config) -> zenoh.Session:
    try:
        session = zenoh.open(config)
    except zenoh.ZError as err:
        raise TransportError(f"cannot open zenoh session: {err}") from err
    LOG.info("zenoh session %s open", session.zid())
    return session
