"""The TCP link to one controller: connect, write wire bytes, read frames, notice a dead link.

Sockets only; what the bytes mean is the codec's (:mod:`shared.openprotocol`).
Reads go through the codec's :class:`~shared.openprotocol.framing.FrameReader`,
so a read that ends inside a message, several messages in one read, a NUL
after a message or none, and garbage between messages are all taken; what
the reader had to skip is counted there (``garbage_bytes``, ``bad_frames``).

A dead link is noticed three ways: the controller closes it (a read of 0
bytes), a read or write fails, or what we wrote is not acknowledged by the
peer's TCP within ``dead_after_s`` (``TCP_USER_TIMEOUT``: a pulled cable under
keep-alives). A silent controller is not a dead one by itself (a controller
that does not mirror keep-alives and has no tightening says nothing): the
session decides on silence (:mod:`.controller_session`). Every end is one
:class:`LinkLostError` naming why.
"""

from __future__ import annotations

import contextlib
import select
import socket
from collections.abc import Collection

from shared.openprotocol import Frame, FrameReader

READ_BYTES = 65536


class LinkLostError(Exception):
    """The link to the controller ended (closed, failed, timed out); the text says why."""


class ControllerLink:
    """One TCP connection to a controller (a context manager: closed on exit)."""

    def __init__(
        self,
        host: str,
        port: int,
        dead_after_s: float,
        known_mids: Collection[int] | None = None,
    ) -> None:
        self.address = f"{host}:{port}"
        self._reader = FrameReader(known_mids=known_mids)
        #: every byte read from the controller (a message coming in pieces is a live link)
        self.bytes_received = 0
        try:
            self._socket = socket.create_connection((host, port), timeout=dead_after_s)
        except OSError as err:
            raise LinkLostError(f"cannot connect to {self.address}: {_why(err)}") from err
        self._socket.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        if hasattr(socket, "TCP_USER_TIMEOUT"):  # Linux: unacknowledged writes end the link
            self._socket.setsockopt(
                socket.IPPROTO_TCP, socket.TCP_USER_TIMEOUT, max(1, round(dead_after_s * 1000))
            )
        self._socket.settimeout(dead_after_s)

    def __enter__(self) -> ControllerLink:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    @property
    def garbage_bytes(self) -> int:
        return self._reader.garbage_bytes

    @property
    def bad_frames(self) -> int:
        return self._reader.bad_frames

    @property
    def pending_bytes(self) -> int:
        """Bytes of a message that has begun to come and is not complete yet."""
        return self._reader.pending_bytes

    def send(self, data: bytes) -> None:
        try:
            self._socket.sendall(data)
        except OSError as err:
            raise LinkLostError(f"write to {self.address} failed: {_why(err)}") from err

    def receive(self, timeout_s: float) -> list[Frame]:
        """The frames that arrive within ``timeout_s`` (none: an empty list)."""
        try:
            readable, _, _ = select.select([self._socket], [], [], max(0.0, timeout_s))
            if not readable:
                return []
            chunk = self._socket.recv(READ_BYTES)
        except OSError as err:
            raise LinkLostError(f"read from {self.address} failed: {_why(err)}") from err
        if not chunk:
            raise LinkLostError(f"{self.address} closed the link")
        self.bytes_received += len(chunk)
        return self._reader.feed(chunk)

    def close(self) -> None:
        with contextlib.suppress(OSError):
            self._socket.shutdown(socket.SHUT_RDWR)
        self._socket.close()


def _why(err: OSError) -> str:
    if isinstance(err, TimeoutError | socket.timeout):
        return "timed out"
    return err.strerror or type(err).__name__
