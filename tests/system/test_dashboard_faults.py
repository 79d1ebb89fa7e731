"""The line's page (``boltwatch serve dashboard``, a real process) against what a network and a
small box can do to it: started before its router, 600 half-open connections under an
open-files limit of 256 (one of 128 raised to its hard limit), malformed requests, event
streams whose clients go away, a flood of run views, paths that are not a run.

Real sockets from this process; no browser (its page is plain HTTP: http.client reads
what a browser's ``GET /`` reads).
"""

from __future__ import annotations

import contextlib
import json
import selectors
import socket
import struct
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import pytest

from shared.results import ResultsStore, store_target
from shared.results.recordings_reading import fill_from_recordings, station_recordings
from tests.benchmarks.run_recordings import record_runs
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


FLOODED_RUNS = 40


def test_a_flood_of_run_views_and_what_is_not_a_run(tmp_path: Path) -> None:
    """The page's process (its connection guard in front) asked every run of st1 at once, 40
    runs of 3000 samples recorded by the real recorder: each answer a view or a 503 in
    words, the board answering meanwhile and every run viewable afterwards; asked what is not
    a run (a run that does not exist, paths out of the recordings and of the page's own
    folder), never served."""
    station = _station(tmp_path, f"tcp/127.0.0.1:{free_port()}", "peer")
    recordings = record_runs(tmp_path / "pre", FLOODED_RUNS, 3000, station_file=station)
    with ResultsStore(store_target(recordings, None)) as store:
        fill_from_recordings(
            store, station_recordings(recordings, ["st1"]), {}, "box", time.time_ns
        )
    with dashboard_process(tmp_path, station) as page:
        for path in (
            "/api/runs/st1/999", "/api/runs/st1/1/files/..%2F..%2Fstation.toml",
            "/api/runs/st1/1/files/%2Fetc%2Fpasswd", "/api/runs/../../etc/passwd",
            "/page/../../station.toml", "/page/%2e%2e/%2e%2e/station.toml",
        ):  # fmt: skip
            status, body = page.get(path)
            assert status in (400, 403, 404), (path, status)
            assert b"root:" not in body and b"[zenoh]" not in body, path

        def view(run_id: int) -> tuple[int, dict[str, Any]]:
            status, body = page.get(f"/api/runs/st1/{run_id}")
            return status, json.loads(body)

        with ThreadPoolExecutor(FLOODED_RUNS) as pool:
            flooded = list(pool.map(view, range(1, FLOODED_RUNS + 1)))
            board = page.board()  # the live side answers meanwhile
        assert board["stations"][0]["station"] == "st1"
        for status, answer in flooded:
            assert status in (200, 503), (status, answer)
            if status == 200:
                assert answer["samples"] == 3000
            else:
                assert answer["errors"][0].endswith("runs for others: ask again in a moment")
        for run_id in range(1, FLOODED_RUNS + 1):  # afterwards, every one of them
            status, answer = view(run_id)
            assert status == 200 and answer["run_id"] == run_id
    log = page.log.read_text()
    assert page.exit_status == 0, log
    assert "Traceback" not in log, log[-3000:]
