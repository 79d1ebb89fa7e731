"""The page's connection guard on a real aiohttp server on loopback, with real sockets.

Idle connections (connected and silent, or a header that never ends) make
room for a new one beyond the bound and are closed after the idle timeout;
a connection beyond a bound of busy ones is closed at once; a request in
progress (a server-sent event stream) is never closed for idleness; a
malformed request (a request line or header too long, too many headers) is
answered 400 and logged as one line, a flood of them as a few.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import AsyncIterator, Callable, Coroutine
from contextlib import asynccontextmanager
from typing import Any

import pytest
from aiohttp import web

from services.dashboard.connection_guard import (
    MAX_CONNECTIONS,
    MAX_FIELD_BYTES,
    MAX_HEADERS,
    MIN_CONNECTIONS,
    RESERVED_FILES,
    ConnectionGuard,
    LoopFaultLog,
    connection_bound,
    handler_options,
)

Reader = asyncio.StreamReader
Writer = asyncio.StreamWriter
#: a guard for a hanging test: far beyond anything these exchanges take
HANG_S = 20.0


@asynccontextmanager
async def serving(guard: ConnectionGuard, release: asyncio.Event) -> AsyncIterator[int]:
    """A real server behind ``guard`` on 127.0.0.1: ``/`` answers at once, ``/slow`` once
    ``release`` is set; yields its port."""

    async def hello(_request: web.Request) -> web.Response:
        return web.Response(text="hello")

    async def slow(_request: web.Request) -> web.Response:
        await release.wait()
        return web.Response(text="late")

    app = web.Application(middlewares=[guard.middleware])
    app.router.add_get("/", hello)
    app.router.add_get("/slow", slow)
    runner = web.AppRunner(app, access_log=None, shutdown_timeout=0.1, **handler_options())
    await runner.setup()
    assert runner.server is not None
    loop = asyncio.get_running_loop()
    listening = await loop.create_server(guard.factory(runner.server), "127.0.0.1", 0)
    sweep = asyncio.create_task(guard.sweep())
    try:
        yield listening.sockets[0].getsockname()[1]
    finally:
        release.set()
        sweep.cancel()
        listening.close()
        await runner.cleanup()


async def _connect(port: int, sent: bytes = b"") -> tuple[Reader, Writer]:
    reader, writer = await asyncio.open_connection("127.0.0.1", port)
    if sent:
        writer.write(sent)
        await writer.drain()
    return reader, writer


async def _get(port: int, path: str = "/", headers: str = "") -> tuple[int, bytes]:
    reader, writer = await _connect(
        port, f"GET {path} HTTP/1.1\r\nHost: x\r\n{headers}Connection: close\r\n\r\n".encode()
    )
    answer = await asyncio.wait_for(reader.read(), HANG_S)
    writer.close()
    return int(answer.split(b" ", 2)[1]), answer


async def _closed_by_server(reader: Reader) -> bool:
    """True when the server closed the connection (EOF or reset), waiting up to HANG_S."""
    try:
        return await asyncio.wait_for(reader.read(1), HANG_S) == b""
    except ConnectionResetError:
        return True


def run(test: Callable[[], Coroutine[Any, Any, None]]) -> None:
    asyncio.run(test())


def test_idle_connections_make_room_and_a_request_is_served() -> None:
    async def test() -> None:
        guard = ConnectionGuard(max_connections=4, idle_timeout_s=HANG_S * 10)
        async with serving(guard, asyncio.Event()) as port:
            idle = [await _connect(port) for _ in range(6)]
            idle.append(await _connect(port, b"GET / HTTP/1.1\r\nHost: x\r\nX-Slow: "))
            status, answer = await _get(port)
            assert status == 200 and answer.endswith(b"hello")
            assert guard.evicted >= 4 and guard.refused == 0
            # the oldest went first: the first three connections were closed by the server
            assert all([await _closed_by_server(reader) for reader, _ in idle[:3]])
            for _, writer in idle:
                writer.close()

    run(test)


def test_beyond_a_bound_of_busy_connections_the_new_one_is_closed() -> None:
    async def test() -> None:
        guard = ConnectionGuard(max_connections=2, idle_timeout_s=HANG_S * 10)
        release = asyncio.Event()
        async with serving(guard, release) as port:
            slow = [asyncio.create_task(_get(port, "/slow")) for _ in range(2)]
            while len(guard._busy) < 2:  # both requests in progress
                await asyncio.sleep(0.01)
            reader, writer = await _connect(port, b"GET / HTTP/1.1\r\nHost: x\r\n\r\n")
            assert await _closed_by_server(reader)
            writer.close()
            assert guard.refused == 1
            release.set()
            assert [status for status, _ in await asyncio.gather(*slow)] == [200, 200]
            assert (await _get(port))[0] == 200

    run(test)


def test_idle_connections_time_out_and_a_stream_in_progress_does_not() -> None:
    async def test() -> None:
        guard = ConnectionGuard(max_connections=16, idle_timeout_s=0.3)
        release = asyncio.Event()
        async with serving(guard, release) as port:
            stream = asyncio.create_task(_get(port, "/slow"))
            silent, _ = await _connect(port)
            half, _ = await _connect(port, b"GET / HTTP/1.1\r\nHost: x\r\n")  # never ends
            assert await _closed_by_server(silent) and await _closed_by_server(half)
            assert guard.timed_out >= 2 and not stream.done()
            release.set()
            assert (await stream)[0] == 200

    run(test)


def test_malformed_requests_are_400_and_one_line_each_kind(
    caplog: pytest.LogCaptureFixture,
) -> None:
    long_header = f"X-Long: {'a' * (MAX_FIELD_BYTES + 10)}\r\n"
    many_headers = "".join(f"X-{n}: {n}\r\n" for n in range(MAX_HEADERS + 10))

    async def test() -> None:
        guard = ConnectionGuard(max_connections=64)
        async with serving(guard, asyncio.Event()) as port:
            assert (await _get(port, "/" + "a" * (MAX_FIELD_BYTES + 10)))[0] in (400, 414)
            for _ in range(20):  # a flood of them
                assert (await _get(port, headers=long_header))[0] in (400, 431)
                assert (await _get(port, headers=many_headers))[0] in (400, 431)
            assert (await _get(port))[0] == 200

    with caplog.at_level(logging.DEBUG, logger="services.dashboard.connection_guard"):
        run(test)
    lines = [r for r in caplog.records if r.name == "services.dashboard.connection_guard"]
    assert lines, "each kind of malformed request is logged once"
    assert len(lines) <= 6, [r.getMessage() for r in lines]  # not one per request: 41 came
    assert all(r.exc_info is None and "\n" not in r.getMessage() for r in lines)


def test_an_event_loop_fault_is_one_line(caplog: pytest.LogCaptureFixture) -> None:
    handler = LoopFaultLog(logging.getLogger("loop-test"))
    error = OSError(24, "Too many open files")
    context: dict[str, Any] = {"message": "socket.accept() out of system resource"}
    loop = asyncio.new_event_loop()
    with caplog.at_level(logging.WARNING, logger="loop-test"):
        for _ in range(1000):
            handler(loop, {**context, "exception": error})
    loop.close()
    (line,) = caplog.records
    assert line.exc_info is None and "OSError: [Errno 24] Too many open files" in line.getMessage()


def test_the_connections_stay_below_the_open_files_limit() -> None:
    assert connection_bound(256) == 256 - RESERVED_FILES
    assert connection_bound(1 << 20) == MAX_CONNECTIONS
    assert connection_bound(16) == MIN_CONNECTIONS
