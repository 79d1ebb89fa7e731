"""A line of hosts in network namespaces, for tests: one line server, N station boxes.

The line server's namespace holds a bridge; each station's namespace is
joined to it by a veth pair created straight into the two namespaces (no
interface ever appears in the namespace the tests run in), so the line's
addresses are private to the test and two tests never collide. Each station
gets its own loopback with the multicast route the simulated CAN bus needs.
``cut`` / ``reconnect`` take a station's cable out and put it back. The
stations' files for such a line (:func:`line_station_files`), its status as
the line server sees it (:func:`line_status`) and the wait for its services
(:func:`wait_until_up`) are here too.

Needs ``ip`` (iproute2) and the right to create namespaces (root or
CAP_SYS_ADMIN); :func:`unavailable_reason` says why not, for a skip.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
import uuid
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

from tests.support.paths import REPO
from tests.support.station_files import write_station

SUBNET = "10.213.0"
SERVER_ADDRESS = f"{SUBNET}.1"
PREFIX = 24


def run_ip(*args: str) -> None:
    """``ip ARGS...`` (iproute2); CalledProcessError when it fails."""
    subprocess.run(["ip", *args], check=True, capture_output=True, text=True, timeout=10)


def unavailable_reason() -> str | None:
    """None when namespaces can be made here; else why not (for ``pytest.skip``)."""
    if shutil.which("ip") is None:
        return "no `ip` command (Debian package iproute2)"
    probe = f"bwprobe{uuid.uuid4().hex[:8]}"
    try:
        run_ip("netns", "add", probe)
    except subprocess.CalledProcessError as err:
        return f"cannot create a network namespace: {err.stderr.strip()}"
    except OSError as err:
        return f"cannot run ip: {err}"
    run_ip("netns", "del", probe)
    return None


@dataclass
class Line:
    """The namespaces of one test; use as a context manager so they always go."""

    stations: int
    tag: str = field(default_factory=lambda: uuid.uuid4().hex[:6])
    _made: list[str] = field(default_factory=list)

    @property
    def server(self) -> str:
        return f"bw{self.tag}srv"

    def station(self, index: int) -> str:
        """Namespace of station ``index`` (1-based)."""
        return f"bw{self.tag}st{index}"

    def station_address(self, index: int) -> str:
        return f"{SUBNET}.{10 + index}"

    def __enter__(self) -> Line:
        try:
            self._build()
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    def _build(self) -> None:
        self._add_namespace(self.server)
        run_ip("-n", self.server, "link", "add", "br0", "type", "bridge")
        run_ip("-n", self.server, "addr", "add", f"{SERVER_ADDRESS}/{PREFIX}", "dev", "br0")
        run_ip("-n", self.server, "link", "set", "br0", "up")
        for index in range(1, self.stations + 1):
            name = self.station(index)
            self._add_namespace(name)
            run_ip("-n", name, "route", "add", "224.0.0.0/4", "dev", "lo")
            cable = self._cable(index)
            run_ip(
                "-n", self.server, "link", "add", cable, "type", "veth", "peer", "name", f"{cable}p"
            )
            run_ip("-n", self.server, "link", "set", cable, "master", "br0")
            run_ip("-n", self.server, "link", "set", f"{cable}p", "netns", name)
            run_ip("-n", name, "link", "set", f"{cable}p", "name", "eth0")
            address = f"{self.station_address(index)}/{PREFIX}"
            run_ip("-n", name, "addr", "add", address, "dev", "eth0")
            run_ip("-n", name, "link", "set", "eth0", "up")
            run_ip("-n", self.server, "link", "set", cable, "up")

    def _cable(self, index: int) -> str:
        return f"cable{index}"

    def _add_namespace(self, name: str) -> None:
        run_ip("netns", "add", name)
        self._made.append(name)
        run_ip("-n", name, "link", "set", "lo", "up")

    def cut(self, index: int) -> None:
        """Pull station ``index``'s cable at the line server's end."""
        run_ip("-n", self.server, "link", "set", self._cable(index), "down")

    def reconnect(self, index: int) -> None:
        run_ip("-n", self.server, "link", "set", self._cable(index), "up")

    def close(self) -> None:
        for name in reversed(self._made):
            subprocess.run(["ip", "netns", "del", name], capture_output=True, check=False)
        self._made.clear()

    def popen(
        self, namespace: str, command: Sequence[str], log: IO[bytes], cwd: Path
    ) -> subprocess.Popen[bytes]:
        """Start ``command`` inside ``namespace`` (``ip netns exec`` execs it: same pid)."""
        return subprocess.Popen(
            ["ip", "netns", "exec", namespace, *command],
            stdout=log,
            stderr=subprocess.STDOUT,
            cwd=cwd,
            env={**os.environ, "PYTHONUNBUFFERED": "1"},
        )

    def boltwatch(
        self, namespace: str, args: Sequence[str], log_path: Path
    ) -> subprocess.Popen[bytes]:
        """``boltwatch ARGS`` of this checkout inside ``namespace``, its output appended to
        ``log_path``."""
        return self.popen(namespace, [*_CLI, *args], log_path.open("ab"), cwd=REPO)

    def run(
        self, namespace: str, command: Sequence[str], cwd: Path, timeout_s: float = 30.0
    ) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            ["ip", "netns", "exec", namespace, *command],
            capture_output=True,
            text=True,
            cwd=cwd,
            timeout=timeout_s,
            check=False,
        )


#: the line's router on the line server
LINE_ENDPOINT = f"tcp/{SERVER_ADDRESS}:7447"
_CLI = [sys.executable, "-m", "services.cli"]


def line_station_files(
    tmp_path: Path, stations: int, extra: str = "", placement: str | None = None
) -> list[Path]:
    """Station files ``st1``..``stN`` for a line's boxes: each a client of the line server's
    router, its own tool and seed, the recordings in ``tmp_path/recordings``; ``extra``
    appended to each (a section)."""
    recordings = tmp_path / "recordings"
    files = []
    for index in range(1, stations + 1):
        folder = tmp_path / f"st{index}"
        folder.mkdir()
        path = write_station(
            folder,
            zenoh_port=7447,
            placement=placement,
            replacements={
                "tcp/127.0.0.1:7447": LINE_ENDPOINT,
                'id = "st1"': f'id = "st{index}"',
                "tool_id = 7": f"tool_id = {100 + index}",
                "seed = 7": f"seed = {index}",
            },
        )
        text = path.read_text().replace(str(folder / "recordings"), str(recordings))
        path.write_text(text + extra.replace("{folder}", str(folder)))
        files.append(path)
    return files


def line_status(line: Line) -> dict[str, dict[str, Any]]:
    """``boltwatch status --json`` as seen from the line server ({} when it failed)."""
    result = line.run(
        line.server,
        [*_CLI, "status", "--connect", LINE_ENDPOINT, "--listen-s", "1.5", "--json"],
        cwd=REPO,
    )
    if result.returncode != 0:
        return {}
    stations: dict[str, dict[str, Any]] = json.loads(result.stdout)["stations"]
    return stations


def wait_until_up(
    line: Line, stations: int, services: Sequence[str], timeout_s: float = 60.0
) -> None:
    """Until every station shows ``services`` alive in the line's status."""
    deadline = time.monotonic() + timeout_s
    status: dict[str, dict[str, Any]] = {}
    while time.monotonic() < deadline:
        status = line_status(line)
        if all(
            (status.get(f"st{i}", {}).get("services") or {}).get(service)
            for i in range(1, stations + 1)
            for service in services
        ):
            return
        time.sleep(0.5)
    raise AssertionError(f"not every station came up in {timeout_s} s: {status}")
