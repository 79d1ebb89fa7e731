"""A TCP proxy between a bridge and an Open Protocol controller that damages the controller's side.

Real sockets on loopback, a thread per direction. What the integrator sends
goes to the controller as it is; what the controller sends is cut into its
messages (4-digit length, NUL terminators passed on as they come) and each
goes to the bridge unless a :class:`Damage` is due on it: the ``nth``
message of its MID since the proxy started (over every link) is

- ``cut``: half of it forwarded, then both sockets closed (a pulled cable);
- ``garbage``: forwarded after a keep-alive header whose length reaches
  past its NUL (a wrong length) and garbage bytes;
- ``rewrite``: forwarded rewritten by a function (same length: a field out of range).

Each damage is done once; :attr:`Damage.done` says when.
"""

from __future__ import annotations

import contextlib
import socket
import threading
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

#: a keep-alive header claiming 40 bytes (it has 20, then a NUL), then bytes no controller sends
GARBAGE = b"\xff\xfe\x13NOT OPEN PROTOCOL\r\n"
WRONG_LENGTH = b"00409999001         \x00"
READ_BYTES = 65536


@dataclass
class Damage:
    """One fault done to the ``nth`` (from 1) message of ``mid`` the controller sends."""

    mid: int
    nth: int
    kind: Literal["cut", "garbage", "rewrite"]
    rewrite: Callable[[bytes], bytes] | None = None
    done: threading.Event = field(default_factory=threading.Event)


class OpenProtocolProxy:
    """Listens on a free loopback port (:attr:`port`) and connects each link to the controller."""

    def __init__(self, controller_port: int) -> None:
        self._controller = ("127.0.0.1", controller_port)
        self._listener = socket.create_server(("127.0.0.1", 0))
        self._listener.settimeout(0.1)
        self.port: int = self._listener.getsockname()[1]
        self._lock = threading.Lock()
        self._damages: list[Damage] = []
        self._seen: Counter[int] = Counter()
        self._sockets: list[socket.socket] = []
        self._stop = threading.Event()
        self.links = 0
        self._thread = threading.Thread(target=self._accept, name="op-proxy", daemon=True)
        self._thread.start()

    def damage(self, damage: Damage) -> Damage:
        with self._lock:
            self._damages.append(damage)
        return damage

    def close(self) -> None:
        self._stop.set()
        self._thread.join(5)
        self._listener.close()
        with self._lock:
            for sock in self._sockets:
                _close(sock)

    def _accept(self) -> None:
        while not self._stop.is_set():
            try:
                bridge, _ = self._listener.accept()
            except TimeoutError:
                continue
            except OSError:
                return
            bridge.settimeout(None)
            try:
                controller = socket.create_connection(self._controller, timeout=2.0)
            except OSError:
                _close(bridge)  # the bridge sees a refused link, as without a proxy
                continue
            controller.settimeout(None)
            with self._lock:
                self._sockets += [bridge, controller]
                self.links += 1
            for target, args in (
                (self._upstream, (bridge, controller)),
                (self._downstream, (controller, bridge)),
            ):
                threading.Thread(
                    target=target, args=args, name="op-proxy-pump", daemon=True
                ).start()

    def _upstream(self, bridge: socket.socket, controller: socket.socket) -> None:
        with contextlib.suppress(OSError):
            while chunk := bridge.recv(READ_BYTES):
                controller.sendall(chunk)
        _close(bridge)
        _close(controller)

    def _downstream(self, controller: socket.socket, bridge: socket.socket) -> None:
        buffer = b""
        with contextlib.suppress(OSError):
            while chunk := controller.recv(READ_BYTES):
                buffer += chunk
                while True:
                    nuls = len(buffer) - len(buffer.lstrip(b"\x00"))
                    if nuls:
                        bridge.sendall(buffer[:nuls])
                        buffer = buffer[nuls:]
                    if len(buffer) < 4 or len(buffer) < int(buffer[:4]):
                        break
                    length = int(buffer[:4])
                    message, buffer = buffer[:length], buffer[length:]
                    if not self._forward(message, controller, bridge):
                        return
        _close(bridge)
        _close(controller)

    def _forward(self, message: bytes, controller: socket.socket, bridge: socket.socket) -> bool:
        """Send ``message`` to the bridge, damaged if a damage is due; False: link cut."""
        mid = int(message[4:8])
        with self._lock:
            self._seen[mid] += 1
            due = next(
                (d for d in self._damages if d.mid == mid and d.nth == self._seen[mid]), None
            )
        if due is None:
            bridge.sendall(message)
            return True
        if due.kind == "cut":
            bridge.sendall(message[: len(message) // 2])
            time.sleep(0.2)  # the bridge reads the half before the link ends
            _close(bridge)
            _close(controller)
            due.done.set()
            return False
        elif due.kind == "garbage":
            bridge.sendall(WRONG_LENGTH + GARBAGE + message)
        else:
            assert due.rewrite is not None
            rewritten = due.rewrite(message)
            assert len(rewritten) == len(message)
            bridge.sendall(rewritten)
        due.done.set()
        return True


def _close(sock: socket.socket) -> None:
    with contextlib.suppress(OSError):
        sock.shutdown(socket.SHUT_RDWR)
    sock.close()
