"""Open the station's CAN bus from configuration (python-can).

``udp_multicast`` carries the embedded simulated station between processes,
``socketcan`` a real station (``can0``), ``virtual`` everything in one process
(tests). All three are ordinary python-can drivers, so the same code path runs
everywhere.
"""

from __future__ import annotations

import logging
from typing import Any

import can

from shared.config.station import CanSection
from shared.errors import TransportError

LOG = logging.getLogger(__name__)


def open_bus(section: CanSection, *, receive_own_messages: bool = False) -> can.BusABC:
    """A python-can bus for ``section``; failure is a TransportError naming the bus."""
    kwargs: dict[str, Any] = {
        "interface": section.interface,
        "channel": section.channel,
        "receive_own_messages": receive_own_messages,
    }
    if section.interface == "udp_multicast":
        kwargs["fd"] = False
        if section.port is not None:
            kwargs["port"] = section.port
    try:
        bus = can.Bus(**kwargs)
    except (can.CanError, OSError, ValueError, ImportError) as err:
        raise TransportError(
            f"cannot open CAN bus {section.interface}:{section.channel}: {err}"
        ) from err
    LOG.info("CAN bus open: %s %s", section.interface, section.channel)
    return bus
