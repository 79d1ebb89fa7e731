"""The page's connections held within bounds: how many, how long idle, and the log they cost.

A line's page is looked at by a few browsers; the network it is on may hold
anything else. What a client can do to the server is bounded here:

- **open files**: the soft limit is raised to the hard one at start
  (:func:`raise_open_files_limit`), and the connections are bounded below it
  (:func:`connection_bound`: the limit less :data:`RESERVED_FILES` for zenoh,
  the results stores, the page's files and the bursts of accepts in flight),
  so the server does not run out of descriptors and ``accept`` does not fail;
- **connections**: at most the bound at once. One more closes the connection
  idle longest (no request in progress: a half-open connection, a header
  that never ends, a keep-alive nobody uses), so a browser's request is
  served while thousands of idle connections come and go; when every one is
  busy (server-sent event streams), the new one is closed, counted;
- **idle connections**: closed after :data:`IDLE_TIMEOUT_S` without a request
  in progress (a server-sent event stream is a request in progress);
- **requests**: the request line and each header at most
  :data:`MAX_FIELD_BYTES`, at most :data:`MAX_HEADERS` headers (aiohttp
  answers 400 and closes);
- **the log**: a malformed request, a client gone mid-answer, a connection
  refused or any error of the event loop is one line (what, from where, the
  error's type and text), never a traceback, each kind at most once per
  10 s with the count of the others (:class:`~shared.runtime.RateLimitedLog`).

The guard uses aiohttp's public surface only: the server's protocol factory
and ``connections``, a middleware that marks requests in progress, each
handler's ``transport`` and ``force_close``.
"""

from __future__ import annotations

import asyncio
import logging
import resource
import time
from collections.abc import Awaitable, Callable
from typing import Any

from aiohttp import web
from aiohttp.web_protocol import RequestHandler

from shared.runtime import RateLimitedLog

LOG = logging.getLogger(__name__)

#: seconds a connection may stay without a request in progress
IDLE_TIMEOUT_S = 10.0
#: connections at most, whatever the open-files limit allows
MAX_CONNECTIONS = 512
#: connections at least, however low the open-files limit (below it, accept may fail)
MIN_CONNECTIONS = 8
#: connections accepted in one go by the event loop (the listening socket's backlog)
ACCEPT_BACKLOG = 32
#: descriptors kept for all but the page's connections: the event loop accepts a burst
#: while the one before it is being handed to the guard and the connections that one
#: replaced are still closing (up to three bursts open beyond the bound, measured: a
#: reserve of one burst ran out under 600 connections at once), and zenoh, the stores,
#: the page's files (14 descriptors when idle)
RESERVED_FILES = 4 * ACCEPT_BACKLOG + 64
#: bytes of the request line and of each header, and headers, at most
MAX_FIELD_BYTES = 8190
MAX_HEADERS = 64
#: the soft open-files limit asked for when the hard one is unlimited
UNBOUNDED_TARGET = 1 << 16
#: how often idle connections are looked for, seconds
SWEEP_S = 1.0


def raise_open_files_limit() -> int:
    """Raise the soft open-files limit to the hard one (what the process may have); the
    soft limit now."""
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if soft == resource.RLIM_INFINITY:
        return MAX_CONNECTIONS + RESERVED_FILES
    target = hard if hard != resource.RLIM_INFINITY else max(soft, UNBOUNDED_TARGET)
    if soft >= target:
        return soft
    try:
        resource.setrlimit(resource.RLIMIT_NOFILE, (target, hard))
    except (ValueError, OSError) as err:
        LOG.warning("open-files limit stays %d (%d was refused: %s)", soft, target, err)
        return soft
    LOG.info("open-files limit raised from %d to %d", soft, target)
    return target


def connection_bound(open_files: int) -> int:
    """How many connections a process allowed ``open_files`` descriptors serves at once."""
    return max(MIN_CONNECTIONS, min(MAX_CONNECTIONS, open_files - RESERVED_FILES))


def handler_options() -> dict[str, Any]:
    """The bounds of a request, as keyword arguments of aiohttp's request handler."""
    return {
        "max_line_size": MAX_FIELD_BYTES,
        "max_field_size": MAX_FIELD_BYTES,
        "max_headers": MAX_HEADERS,
        "logger": ClientFaultLog(LOG),
    }


class ConnectionGuard:
    """Bounds the connections of one aiohttp server (see the module docstring)."""

    def __init__(
        self,
        max_connections: int,
        idle_timeout_s: float = IDLE_TIMEOUT_S,
        clock_s: Callable[[], float] = time.monotonic,
    ) -> None:
        self.max_connections = max_connections
        self.idle_timeout_s = idle_timeout_s
        self._clock_s = clock_s
        # every connection made, until closed here (one the client closed stays until the
        # sweep or an eviction takes it: it is idle, so it never holds a place)
        self._last_active_s: dict[RequestHandler, float] = {}
        self._busy: dict[RequestHandler, int] = {}  # requests in progress
        self.refused = 0  # new connections closed: every one was busy
        self.evicted = 0  # idle connections closed to make room
        self.timed_out = 0  # idle connections closed after the idle timeout
        self._refused_log = RateLimitedLog(LOG)

    def factory(self, server: web.Server) -> Callable[[], asyncio.BaseProtocol]:
        """The protocol factory to listen with: ``server``'s, within the bound."""

        def make() -> asyncio.BaseProtocol:
            if len(self._last_active_s) >= self.max_connections and not self._evict_idlest():
                self.refused += 1
                self._refused_log(
                    "connection refused: %d connections open, each with a request in "
                    "progress (%d refused so far)",
                    len(self._last_active_s),
                    self.refused,
                )
                return _Refused()
            handler = server()
            self._last_active_s[handler] = self._clock_s()
            return handler

        return make

    @web.middleware
    async def middleware(
        self,
        request: web.Request,
        handler: Callable[[web.Request], Awaitable[web.StreamResponse]],
    ) -> web.StreamResponse:
        """Marks the request in progress (its connection is not idle) until it is answered."""
        protocol = request.protocol
        self._busy[protocol] = self._busy.get(protocol, 0) + 1
        try:
            return await handler(request)
        finally:
            left = self._busy.pop(protocol) - 1
            if left:
                self._busy[protocol] = left
            if protocol in self._last_active_s:
                self._last_active_s[protocol] = self._clock_s()

    async def sweep(self) -> None:
        """Close idle connections past the timeout, every :data:`SWEEP_S`, until cancelled."""
        while True:
            await asyncio.sleep(SWEEP_S)
            self.close_idle()

    def close_idle(self) -> int:
        """Close every connection idle past the timeout now (and forget those the client
        closed: they are idle too); how many."""
        limit_s = self._clock_s() - self.idle_timeout_s
        idle = [
            handler
            for handler, active_s in self._last_active_s.items()
            if handler not in self._busy and active_s < limit_s
        ]
        for handler in idle:
            _close(handler)
            del self._last_active_s[handler]
        self.timed_out += len(idle)
        return len(idle)

    def _evict_idlest(self) -> bool:
        idle = [
            (active_s, id(handler), handler)
            for handler, active_s in self._last_active_s.items()
            if handler not in self._busy
        ]
        if not idle:
            return False
        _, _, handler = min(idle)
        _close(handler)
        del self._last_active_s[handler]
        self.evicted += 1
        return True


def _close(handler: RequestHandler) -> None:
    transport = handler.transport
    handler.force_close()
    if transport is not None:
        transport.abort()


class _Refused(asyncio.Protocol):
    """A connection beyond the bound: closed as soon as it is made."""

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        assert isinstance(transport, asyncio.Transport)
        transport.abort()


class ClientFaultLog:
    """The logger of aiohttp's request handlers: what a client did wrong (a malformed
    request, a reset) as one line, each kind rate-limited; never a traceback."""

    def __init__(self, logger: logging.Logger) -> None:
        self._logger = logger
        self._kinds: dict[str, RateLimitedLog] = {}

    def _line(self, level: int, message: str, *args: Any, **kwargs: Any) -> None:
        error = kwargs.get("exc_info")
        text = message % args if args else message
        kind = message if not isinstance(error, BaseException) else type(error).__name__
        if isinstance(error, BaseException):
            text = f"{text}: {type(error).__name__}: {_first_line(error)}"
        limited = self._kinds.get(kind)
        if limited is None:
            limited = self._kinds[kind] = RateLimitedLog(self._logger, level)
        limited("%s", text)

    def exception(self, message: str, *args: Any, **kwargs: Any) -> None:
        self._line(logging.WARNING, message, *args, **kwargs)

    def error(self, message: str, *args: Any, **kwargs: Any) -> None:
        self._line(logging.WARNING, message, *args, **kwargs)

    def warning(self, message: str, *args: Any, **kwargs: Any) -> None:
        self._line(logging.WARNING, message, *args, **kwargs)

    def info(self, message: str, *args: Any, **kwargs: Any) -> None:
        self._line(logging.INFO, message, *args, **kwargs)

    def debug(self, message: str, *args: Any, **kwargs: Any) -> None:
        if self._logger.isEnabledFor(logging.DEBUG):
            self._line(logging.DEBUG, message, *args, **kwargs)


def _first_line(error: BaseException) -> str:
    """What went wrong in one line (aiohttp's HTTP errors keep it in ``message``)."""
    message = getattr(error, "message", None)
    text = message if isinstance(message, str) and message else str(error)
    return " ".join(text.split())


class LoopFaultLog:
    """The event loop's exception handler: one line per fault (an ``accept`` that failed,
    a callback that raised), each kind rate-limited; never a traceback."""

    def __init__(self, logger: logging.Logger) -> None:
        self._logger = logger
        self._kinds: dict[str, RateLimitedLog] = {}

    def __call__(self, _loop: asyncio.AbstractEventLoop, context: dict[str, Any]) -> None:
        message = str(context.get("message", "event loop error"))
        error = context.get("exception")
        kind = f"{message}/{type(error).__name__}"
        limited = self._kinds.get(kind)
        if limited is None:
            limited = self._kinds[kind] = RateLimitedLog(self._logger)
        if isinstance(error, BaseException):
            limited("%s: %s: %s", message, type(error).__name__, _first_line(error))
        else:
            limited("%s", message)
