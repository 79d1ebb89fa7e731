"""A line of hosts in network namespaces, for tests: one line server, N station boxes.

The line server's namespace holds a bridge; each station's namespace is
joined to it by a veth pair created straight into the two namespaces (no
interface ever appears in the namespace the tests run in), so the line's
addresses are private to the test and two tests never collide. Each station
gets its own loopback with the multicast route the simulated CAN bus needs.
``cut`` / ``reconnect`` take a station's cable out and put it back.

Needs ``ip`` (iproute2) and the right to create namespaces (root or
CAP_SYS_ADMIN); :func:`unavailable_reason` says why not, for a skip.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import uuid
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

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
