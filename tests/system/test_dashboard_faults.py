"""The line's page (``boltwatch serve dashboard``, a real process) against what a network and a
small box can do to it: started before its router, 600 half-open connections under an
open-files limit of 256 (one of 128 raised to its hard limit), malformed requests, event
streams whose clients go away.

Real sockets from this process; no browser (its page is plain HTTP: http.client reads
what a browser's ``GET /`` reads).
"""

from __future__ import annotations

import contextlib
import selectors
import socket
import struct
import time
from pathlib import Path

import pytest

from tests.support.dashboard_process import dashboard_process
from tests.support.live_recorder import free_port, write_station_file
from tests.support.router_process import router_process

pytestmark = pytest.mark.system

#: a failure past it, not a figure: the router link comes up in milliseconds
REACH_S = 30.0
HALF_OPEN = 600


def _station(tmp_path: Path, endpoint: str, mode: str) -> Path:
    path = write_station_file(
        tmp_path / "station.toml", tmp_path / "recordings", connect=[endpoint]
    )
    text = path.read_text().replace('mode = "peer"', f'mode = "{mode}"')
    path.write_text(text)
    return path


def test_the_page_is_served_before_its_router_and_says_what_it_cannot_reach(
    tmp_path: Path,
) -> None:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    station = _station(tmp_path, endpoint, "client")  # a client waits for its router
    with dashboard_process(tmp_path, station, open_files=(128, 1024)) as page:
        assert page.open_files_limit() == (1024, 1024)  # raised to what it may have
        status, body = page.get("/")
        assert status == 200 and b'id="router"' in body
        router = page.board()["router"]
        assert router["reachable"] is False and router["endpoints"] == endpoint
        with router_process(tmp_path, endpoint):
            deadline = time.monotonic() + REACH_S
            while not page.board()["router"]["reachable"]:
                assert time.monotonic() < deadline, page.log.read_text()
                time.sleep(0.2)
    assert page.exit_status == 0, page.log.read_text()


def _reset(connection: socket.socket) -> None:
    """Close with a reset (RST), as a browser killed mid-stream does."""
    connection.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
    connection.close()


def _half_open(port: int, count: int) -> list[socket.socket]:
    """``count`` connections made at once (a third of them in the middle of a header), as
    a client holding them open and saying nothing more does."""
    connections = []
    with selectors.DefaultSelector() as waiting:
        for _ in range(count):
            connection = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            connection.setblocking(False)
            connection.connect_ex(("127.0.0.1", port))
            waiting.register(connection, selectors.EVENT_WRITE)
            connections.append(connection)
        deadline = time.monotonic() + REACH_S
        while waiting.get_map():
            assert time.monotonic() < deadline, f"{len(waiting.get_map())} never connected"
            for key, _ in waiting.select(1.0):
                waiting.unregister(key.fileobj)
    for connection in connections[::3]:
        with contextlib.suppress(OSError):  # one the page closed already to make room
            connection.send(b"GET / HTTP/1.1\r\nHost: x\r\nX-Slow: ")
    return connections


def _raw(port: int, request: bytes) -> bytes:
    with socket.create_connection(("127.0.0.1", port), timeout=30) as connection:
        connection.sendall(request)
        answer = b""
        while chunk := connection.recv(65536):
            answer += chunk
        return answer


def test_half_open_connections_a_low_open_files_limit_and_hostile_clients(
    tmp_path: Path,
) -> None:
    station = _station(tmp_path, f"tcp/127.0.0.1:{free_port()}", "peer")
    with dashboard_process(tmp_path, station, open_files=(256, 256)) as page:
        assert page.open_files_limit() == (256, 256)
        half_open = _half_open(page.port, HALF_OPEN)
        status, body = page.get("/")  # a browser's GET / among them
        assert status == 200 and b"boltwatch: the line" in body
        status, _ = page.get("/board.json")
        assert status == 200
        too_long = b"GET /" + b"a" * 10_000 + b" HTTP/1.1\r\nHost: x\r\n\r\n"
        many = b"GET / HTTP/1.1\r\n" + b"".join(b"X-%d: 1\r\n" % n for n in range(200)) + b"\r\n"
        for request in (too_long, many) * 10:
            assert _raw(page.port, request).split(b" ", 2)[1] in (b"400", b"414", b"431")
        for _ in range(20):  # event streams whose browsers are killed
            stream = socket.create_connection(("127.0.0.1", page.port), timeout=30)
            stream.sendall(b"GET /events HTTP/1.1\r\nHost: x\r\n\r\n")
            assert stream.recv(4096).startswith(b"HTTP/1.1 200")
            _reset(stream)
        assert page.get("/")[0] == 200
        for connection in half_open:
            connection.close()
    log = page.log.read_text()
    assert page.exit_status == 0, log
    assert "Traceback" not in log and "Too many open files" not in log, log[-3000:]
    assert len(log.splitlines()) < 40, log[-3000:]  # one line a kind, not one a client
