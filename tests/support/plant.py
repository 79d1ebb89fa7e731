"""A plant of two lines for system tests: per line a router, a recorder and one station.

Line K (1 and 2) has its router (``serve router``; line 2's with ``--connect``
to line 1's), its recorder for its one station ``stK`` only, and the station's
acquisition (with its edge predictor) and simulated rig, all as real
processes; each line's services connect to their own router only. Where the
lines run is a :class:`Hosts`: both on this host's loopback (two router
ports), or each line in its own network namespace, joined by a veth pair
(:class:`NamespacePlant`: ``ip``, as root).

Every station uses tool ``TOOL_ID``: one tool that has worked on both lines
(a plant asset), so its wear is in two ledgers and only a merge of both
recorders' replies gives its whole total.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
import uuid
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

from mcap.reader import make_reader

from services.cli.station_supervisor import stop_processes
from tests.support.netns_line import run_ip
from tests.support.paths import REPO
from tests.support.station_files import free_tcp_port, write_station

LINES = (1, 2)
#: the plant both lines are in ([station] plant)
PLANT = "North"
TOOL_ID = 31
CLI = [sys.executable, "-m", "services.cli"]
#: the plant's own subnet (test_netns_line.py uses 10.213.0.0/24)
SUBNET = "10.214.0"


class Hosts(Protocol):
    """Where each line runs: its router's endpoint, and a command's prefix to run there."""

    def endpoint(self, line: int) -> str: ...

    def prefix(self, line: int) -> list[str]: ...


@dataclass
class LoopbackPlant:
    """Both lines on this host: two routers on two free ports."""

    ports: dict[int, int] = field(default_factory=lambda: {n: free_tcp_port() for n in LINES})

    def endpoint(self, line: int) -> str:
        return f"tcp/127.0.0.1:{self.ports[line]}"

    def prefix(self, line: int) -> list[str]:
        return []


@dataclass
class NamespacePlant:
    """Each line server in its own network namespace, the two joined by one veth pair
    (the cable between the lines); each has its own loopback with the multicast route
    its simulated CAN bus needs. A context manager: the namespaces always go."""

    tag: str = field(default_factory=lambda: uuid.uuid4().hex[:6])
    _made: list[str] = field(default_factory=list)

    def namespace(self, line: int) -> str:
        return f"bw{self.tag}line{line}"

    def address(self, line: int) -> str:
        return f"{SUBNET}.{line}"

    def endpoint(self, line: int) -> str:
        return f"tcp/{self.address(line)}:7447"

    def prefix(self, line: int) -> list[str]:
        return ["ip", "netns", "exec", self.namespace(line)]

    def __enter__(self) -> NamespacePlant:
        try:
            for line in LINES:
                name = self.namespace(line)
                run_ip("netns", "add", name)
                self._made.append(name)
                run_ip("-n", name, "link", "set", "lo", "up")
                run_ip("-n", name, "route", "add", "224.0.0.0/4", "dev", "lo")
            one, two = (self.namespace(line) for line in LINES)
            run_ip("-n", one, "link", "add", "plant0", "type", "veth", "peer", "name", "plant1")
            run_ip("-n", one, "link", "set", "plant1", "netns", two)
            for line, device in zip(LINES, ("plant0", "plant1"), strict=True):
                name = self.namespace(line)
                run_ip("-n", name, "addr", "add", f"{self.address(line)}/24", "dev", device)
                run_ip("-n", name, "link", "set", device, "up")
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    def close(self) -> None:
        for name in reversed(self._made):
            subprocess.run(["ip", "netns", "del", name], capture_output=True, check=False)
        self._made.clear()


def line_station(folder: Path, hosts: Hosts, line: int, results_database: str | None) -> Path:
    """Station ``st<line>`` of line ``line`` (``[station] line = "line<line>"``, in plant
    :data:`PLANT`, named ``Station <line>``): its router,
    its recordings folder, the plant's results store (none: its own, in its recordings)."""
    station = folder / f"line{line}"
    station.mkdir()
    port = free_tcp_port()
    flush = "flush_interval_s = 1.0"
    database = f'\nresults_database = "{results_database}"' if results_database else ""
    return write_station(
        station,
        zenoh_port=port,
        replacements={
            f"tcp/127.0.0.1:{port}": hosts.endpoint(line),
            'id = "st1"': f'id = "st{line}"\nplant = "{PLANT}"\nline = "line{line}"\n'
            f'name = "Station {line}"',
            "tool_id = 7": f"tool_id = {TOOL_ID}",
            "seed = 7": f"seed = {line}",
            flush: flush + database,
        },
    )


@dataclass
class Plant:
    """The processes of the two lines, started in order; ``stop`` ends them all."""

    hosts: Hosts
    folder: Path
    results_database: str | None = None  # the plant's PostgreSQL; none: a store per line
    stations: dict[int, Path] = field(default_factory=dict)
    processes: list[subprocess.Popen[bytes]] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.logs = self.folder / "logs"
        self.logs.mkdir(parents=True, exist_ok=True)
        for line in LINES:
            self.stations[line] = line_station(self.folder, self.hosts, line, self.results_database)

    def recordings(self, line: int) -> Path:
        return self.stations[line].parent / "recordings"

    def start(self, line: int, name: str, args: Sequence[str]) -> subprocess.Popen[bytes]:
        with (self.logs / f"{name}.log").open("ab") as log:
            process = subprocess.Popen(
                [*self.hosts.prefix(line), *CLI, *args],
                stdout=log,
                stderr=subprocess.STDOUT,
                cwd=REPO,
                env={**os.environ, "PYTHONUNBUFFERED": "1"},
            )
        self.processes.append(process)
        return process

    def start_lines(self) -> None:
        """Routers (line 2's meshed with line 1's), recorders, acquisitions."""
        for line in LINES:
            mesh = ["--connect", self.hosts.endpoint(1)] if line == 2 else []
            listen = ["--listen", self.hosts.endpoint(line)]
            self.start(line, f"router{line}", ["serve", "router", *listen, *mesh])
        for line in LINES:
            config = ["--config", str(self.stations[line])]
            self.start(line, f"recorder{line}", ["serve", "recorder", "--no-rerun", *config])
            self.start(line, f"acquisition{line}", ["serve", "acquisition", *config])

    def start_rigs(self, runs: int) -> list[subprocess.Popen[bytes]]:
        rig = ["serve", "rig", "--runs", str(runs), "--program", "2", "--config"]
        return [self.start(line, f"rig{line}", [*rig, str(self.stations[line])]) for line in LINES]

    def cli(self, line: int, args: Sequence[str]) -> subprocess.CompletedProcess[str]:
        """A ``boltwatch`` command on line ``line``, asking its router."""
        return subprocess.run(
            [*self.hosts.prefix(line), *CLI, *args, "--connect", self.hosts.endpoint(line)],
            capture_output=True,
            text=True,
            cwd=REPO,
            timeout=60,
            check=False,
        )

    def status(self, line: int) -> dict[str, Any]:
        """``boltwatch status --json`` on line ``line``: its stations by id ({} on failure)."""
        result = self.cli(line, ["status", "--listen-s", "1.5", "--json"])
        if result.returncode != 0:
            return {}
        stations: dict[str, Any] = json.loads(result.stdout)["stations"]
        return stations

    def wear(self, line: int) -> list[dict[str, Any]]:
        """``boltwatch wear --plant --json`` on line ``line``."""
        result = self.cli(line, ["wear", "--json"])
        assert result.returncode == 0, result.stdout + result.stderr
        tools: list[dict[str, Any]] = json.loads(result.stdout)
        return tools

    def wait_until_up(self, timeout_s: float = 40.0) -> None:
        """Every station's acquisition, predictor and recorder seen from line 1."""
        deadline = time.monotonic() + timeout_s
        status: dict[str, Any] = {}
        while time.monotonic() < deadline:
            status = self.status(1)
            if all(
                status.get(f"st{line}", {}).get("services", {}).get(service)
                for line in LINES
                for service in ("acquisition", "predictor", "recorder")
            ):
                return
            time.sleep(0.5)
        raise AssertionError(f"the plant did not come up in {timeout_s} s: {status}; {self.logs}")

    def stop(self) -> None:
        stop_processes(list(reversed(self.processes)))


def recorded_topics(recordings: Path) -> dict[str, int]:
    """Messages per MCAP channel topic of every recording under ``recordings``."""
    counts: dict[str, int] = {}
    for path in sorted(recordings.rglob("*.mcap")):
        with path.open("rb") as handle:
            for _schema, channel, _message in make_reader(handle).iter_messages():
                counts[channel.topic] = counts.get(channel.topic, 0) + 1
    return counts
