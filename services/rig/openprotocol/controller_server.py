"""The simulated controller's TCP side: one listening socket, the integrators' links, one thread.

:meth:`ControllerServer.serve` is a ``selectors`` loop: it accepts
integrators (at most :data:`MAX_LINKS` at once, as a controller takes a few;
one more is closed at once and counted), feeds each read to its
:class:`~.integrator_link.IntegratorLink`, writes what the link has to say,
runs the links' timers (acknowledge time-outs, silent links), and hands every
tightening the tool finished (:meth:`report`, from the tool's thread: a
queue and a wake-up byte) to the controller state and to every link. A link
that must end is written out, then closed: its subscriptions end with it,
the results stay in the store.

Writes are blocking with a timeout (:data:`WRITE_TIMEOUT_S`): an integrator
that takes nothing for that long is dropped (counted as closed), it cannot
stall the controller for longer.
"""

from __future__ import annotations

import contextlib
import logging
import queue
import selectors
import socket
import threading
import time
from collections.abc import Callable

from services.rig.openprotocol.controller_state import ControllerState
from services.rig.openprotocol.integrator_link import IntegratorLink
from services.rig.openprotocol.tightening import Tightening
from shared.errors import TransportError

LOG = logging.getLogger(__name__)

MAX_LINKS = 4
WRITE_TIMEOUT_S = 5.0
READ_BYTES = 65536
#: the longest the loop sleeps when no timer is due (it also wakes on any socket)
IDLE_WAIT_S = 0.2


class ControllerServer:
    """Listens on ``host:port`` from construction; :meth:`close` (or ``with``) releases it."""

    def __init__(
        self,
        host: str,
        port: int,
        state: ControllerState,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._state = state
        self._clock = clock
        try:
            self._listener = socket.create_server((host, port), backlog=MAX_LINKS)
        except OSError as err:
            raise TransportError(
                f"the simulated controller cannot listen on {host}:{port}: {err.strerror or err}"
            ) from err
        self._listener.setblocking(False)
        self._wake_in, self._wake_out = socket.socketpair()
        self._wake_in.setblocking(False)
        self._wake_out.setblocking(False)
        #: finished tightenings, and a multi-spindle system's cycles (each a list of them)
        self._inbox: queue.SimpleQueue[Tightening | list[Tightening]] = queue.SimpleQueue()
        self._links: dict[socket.socket, IntegratorLink] = {}
        self._selector = selectors.DefaultSelector()
        self._selector.register(self._listener, selectors.EVENT_READ, "accept")
        self._selector.register(self._wake_in, selectors.EVENT_READ, "wake")
        #: results pushed or queued to a link and not yet acknowledged (read from any thread)
        self.outstanding = 0

    def __enter__(self) -> ControllerServer:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    @property
    def port(self) -> int:
        """The port listened on (the one asked, or the one the system gave for 0)."""
        return int(self._listener.getsockname()[1])

    @property
    def connected(self) -> int:
        return len(self._links)

    @property
    def links(self) -> list[IntegratorLink]:
        """The integrators' sessions now (the serving thread's; a test reads them after)."""
        return list(self._links.values())

    def report(self, tightening: Tightening) -> None:
        """A finished tightening (any thread): kept and pushed by the serving thread."""
        self._inbox.put(tightening)
        with contextlib.suppress(OSError):  # the wake-up pipe is full: the loop is awake anyway
            self._wake_out.send(b"\x00")

    def report_cycle(self, cycle: list[Tightening]) -> None:
        """A multi-spindle system's cycle (any thread), after its spindles' tightenings: its
        status (0091) and result (0101) pushed by the serving thread."""
        self._inbox.put(cycle)
        with contextlib.suppress(OSError):
            self._wake_out.send(b"\x00")

    def serve(self, stop: threading.Event, until: Callable[[], bool] = lambda: False) -> None:
        """Serve until ``stop`` is set or ``until()`` says so (asked every turn)."""
        while not stop.is_set() and not until():
            now = self._clock()
            due = min((link.deadline() for link in self._links.values()), default=now + 1.0)
            wait_s = min(IDLE_WAIT_S, max(0.0, due - now))
            for key, _ in self._selector.select(wait_s):
                if key.data == "accept":
                    self._accept()
                elif key.data == "wake":
                    self._drain_wake()
                else:
                    self._read(key.fileobj)  # type: ignore[arg-type]
            now = self._clock()
            self._take_tightenings(now)
            for sock, link in list(self._links.items()):
                link.tick(now)
                self._flush(sock, link)
            self.outstanding = sum(link.outstanding for link in self._links.values())
        self._take_tightenings(self._clock())  # kept, even if nobody hears of them now

    def close(self) -> None:
        for sock in list(self._links):
            self._end(sock, "the controller stops")
        self._selector.close()
        for sock in (self._listener, self._wake_in, self._wake_out):
            sock.close()

    # -- pieces ------------------------------------------------------------------------

    def _accept(self) -> None:
        try:
            sock, address = self._listener.accept()
        except BlockingIOError:
            return
        peer = f"{address[0]}:{address[1]}"
        if len(self._links) >= MAX_LINKS:
            LOG.warning("%s: refused, %d integrators connected already", peer, MAX_LINKS)
            self._state.counters.links_refused += 1
            sock.close()
            return
        sock.settimeout(WRITE_TIMEOUT_S)
        self._links[sock] = IntegratorLink(peer, self._state, self._clock())
        self._selector.register(sock, selectors.EVENT_READ, "link")
        self._state.counters.links += 1
        LOG.info("%s: integrator connected (%d connected)", peer, len(self._links))

    def _read(self, sock: socket.socket) -> None:
        link = self._links[sock]
        try:
            chunk = sock.recv(READ_BYTES)
        except OSError as err:
            self._end(sock, f"read failed: {err}")
            return
        if not chunk:
            self._end(sock, "the integrator closed the link")
            return
        link.receive(chunk, self._clock())
        self._flush(sock, link)

    def _flush(self, sock: socket.socket, link: IntegratorLink) -> None:
        data = link.take_output()
        if data:
            try:
                sock.sendall(data)
            except OSError as err:
                self._end(sock, f"write failed: {err}")
                return
        if link.closed is not None:
            self._end(sock, None)

    def _end(self, sock: socket.socket, why: str | None) -> None:
        link = self._links.pop(sock)
        if why is not None:  # not ended by the link itself (which counted and logged why)
            self._state.counters.drops_closed += 1
            LOG.info("%s: link ended: %s", link.peer, why)
        self._selector.unregister(sock)
        sock.close()

    def _drain_wake(self) -> None:
        try:
            while self._wake_in.recv(4096):
                pass
        except BlockingIOError:
            pass

    def _take_tightenings(self, now: float) -> None:
        while True:
            try:
                tightening = self._inbox.get_nowait()
            except queue.Empty:
                return
            if isinstance(tightening, list):  # a cycle, after its tightenings
                for sock, link in list(self._links.items()):
                    link.cycle(tightening)
                    self._flush(sock, link)
                continue
            alarms = self._state.tightening(tightening)
            for sock, link in list(self._links.items()):
                link.tightening(tightening, now)
                for alarm in alarms:
                    link.alarm_message(alarm)
                self._flush(sock, link)
