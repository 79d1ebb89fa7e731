"""``boltwatch serve dashboard`` as a process of a test: started (under an open-files limit of
the test's choosing), its page awaited, stopped with SIGTERM, its log kept; a page's URL
awaited (:func:`wait_http`)."""

from __future__ import annotations

import contextlib
import http.client
import json
import subprocess
import sys
import time
import urllib.request
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from services.cli.station_supervisor import stop_process
from tests.support.live_recorder import free_port
from tests.support.paths import REPO

#: how long a page may take to come up on a loaded machine (a failure past it, not a figure)
START_S = 60.0
#: sets RLIMIT_NOFILE, then runs the rest of the command line in the same process
_LIMITED = (
    "import os, resource, sys; "
    "resource.setrlimit(resource.RLIMIT_NOFILE, (int(sys.argv[1]), int(sys.argv[2]))); "
    "os.execv(sys.executable, [sys.executable, *sys.argv[3:]])"
)


@dataclass
class DashboardProcess:
    """A running page: its process, port and log."""

    process: subprocess.Popen[bytes]
    port: int
    log: Path
    exit_status: int | None = None

    def get(self, path: str, timeout_s: float = 30.0) -> tuple[int, bytes]:
        """GET ``path`` as a browser does (a new connection): status and body."""
        connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=timeout_s)
        try:
            connection.request("GET", path)
            response = connection.getresponse()
            return response.status, response.read()
        finally:
            connection.close()

    def board(self) -> dict[str, Any]:
        status, body = self.get("/board.json")
        assert status == 200, body
        document: dict[str, Any] = json.loads(body)
        return document

    def open_files_limit(self) -> tuple[int, int]:
        """The process's (soft, hard) open-files limit, from /proc."""
        for line in Path(f"/proc/{self.process.pid}/limits").read_text().splitlines():
            if line.startswith("Max open files"):
                soft, hard = line.split()[3:5]
                return int(soft), int(hard)
        raise AssertionError("no open-files limit in /proc")


@contextlib.contextmanager
def dashboard_process(
    tmp_path: Path, station_file: Path, open_files: tuple[int, int] | None = None
) -> Iterator[DashboardProcess]:
    """``serve dashboard --config station_file`` (``open_files``: its (soft, hard) limit at
    start); yields once ``GET /`` answers 200; stopped with SIGTERM after (exit status kept)."""
    port = free_port()
    command = ["-m", "services.cli", "serve", "dashboard", "--config", str(station_file)]
    command += ["--listen", f"127.0.0.1:{port}"]
    if open_files is not None:
        command = ["-c", _LIMITED, *map(str, open_files), *command]
    log = tmp_path / f"dashboard-{port}.log"
    with log.open("wb") as output:
        process = subprocess.Popen(
            [sys.executable, *command], cwd=REPO, stdout=output, stderr=subprocess.STDOUT
        )
    page = DashboardProcess(process, port, log)
    try:
        deadline = time.monotonic() + START_S
        while True:
            assert process.poll() is None, log.read_text()
            try:
                if page.get("/", timeout_s=5)[0] == 200:
                    break
            except OSError:
                assert time.monotonic() < deadline, f"no page within {START_S} s: {log.read_text()}"
                time.sleep(0.2)
        yield page
    finally:
        page.exit_status = stop_process(process, grace_s=10)


def wait_http(url: str, timeout_s: float = START_S) -> None:
    """Until ``GET url`` answers 200 (OSError past ``timeout_s``)."""
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            with urllib.request.urlopen(url, timeout=2) as response:
                if response.status == 200:
                    return
        except OSError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.2)
