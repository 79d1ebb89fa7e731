"""Open the station's CAN bus from configuration (python-can).

``udp_multicast`` carries the embedded simulated station between processes,
``socketcan`` a real station (``can0``), ``virtual`` everything in one process
(tests). All three are ordinary python-can drivers, so the same code path runs
everywhere.
"""

from __future__ import annotations

import logging
import socket
from typing import Any

import can

from shared.config import CanSection
from shared.errors import TransportError

LOG = logging.getLogger(__name__)

#: Receive buffer asked for on a ``udp_multicast`` bus: the kernel's default
#: (about 200 KiB, some 270 frames, 0.1 s at 1 kHz) loses samples whenever the
#: acquisition is descheduled that long on a busy box; 4 MiB rides out
#: seconds. The kernel caps it at ``net.core.rmem_max``.
UDP_RECEIVE_BUFFER_BYTES = 4 * 1024 * 1024


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
    if section.interface == "udp_multicast":
        _enlarge_receive_buffer(bus)
    LOG.info("CAN bus open: %s %s", section.interface, section.channel)
    return bus


def _enlarge_receive_buffer(bus: can.BusABC) -> None:
    """Ask for :data:`UDP_RECEIVE_BUFFER_BYTES` on the bus's socket; log what was granted."""
    view = socket.socket(fileno=bus.fileno())  # the bus's own socket, not a new one
    try:
        view.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, UDP_RECEIVE_BUFFER_BYTES)
        granted = view.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF)
    except OSError as err:
        LOG.warning("cannot enlarge the CAN socket's receive buffer: %s", err)
        return
    finally:
        view.detach()  # the bus owns the descriptor
    LOG.info("CAN socket receive buffer: %d KiB", granted // 1024)
