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
    mode: str, connect: Sequence[str] = (), listen: Sequence[str] = ()
) -> zenoh.Config:
    """A zenoh.Config with ``mode``, endpoints, and multicast scouting off."""
    config = zenoh.Config()
    config.insert_json5("mode", json.dumps(mode))
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("connect/endpoints", json.dumps(list(connect)))
    config.insert_json5("listen/endpoints", json.dumps(list(listen)))
    if mode == "client":
        # Keep trying to reach the router for ever: it may start later or restart.
        config.insert_json5("connect/timeout_ms", "-1")
    return config


def open_session(section: ZenohSection) -> zenoh.Session:
    """Open a session for a station service; errors name the endpoints tried."""
    return open_from(zenoh_config(section.mode, section.connect, section.listen))


def open_from(config: zenoh.Config) -> zenoh.Session:
    try:
        session = zenoh.open(config)
    except zenoh.ZError as err:
        raise TransportError(f"cannot open zenoh session: {err}") from err
    LOG.info("zenoh session %s open", session.zid())
    return session
