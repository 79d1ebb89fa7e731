"""docker-compose.tls.yml's services run on loopback: the commands compose would run.

Certificates come from config/security/make-compose-certs.sh; the compose files
are merged as ``docker compose -f docker-compose.yml -f docker-compose.tls.yml``
merges them (:mod:`tests.support.compose_layout`). Each service runs as
``python -m services.cli`` with the exact arguments of its merged command, in a
copy of what its container sees (config, its own identity, the OPC UA server's
files, the recordings), with what loopback needs changed: the router is
``127.0.0.1`` on a free port instead of ``router:7447`` (the router's
certificate names 127.0.0.1 too), the station's CAN multicast port is a free
one, and the line's page and the OPC UA server listen on free ports of
127.0.0.1. Health checks run as the containers run them: ``boltwatch health
...`` with that container's identity.
"""

from __future__ import annotations

import contextlib
import re
import subprocess
import time
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import zenoh

from services.cli.station_supervisor import stop_process
from shared.config import load_station
from shared.runtime import open_session
from tests.support.compose_layout import (
    BASE_FILE,
    IDENTITY,
    TLS_FILE,
    ContainerFiles,
    load_merged,
    make_compose_certs,
    split_volume,
)
from tests.support.router_process import boltwatch
from tests.support.station_files import free_tcp_port, free_udp_port, serve

TLS_STATIONS = "/etc/boltwatch/compose/tls"


#: ``boltwatch health``'s status for a service not alive (yet)
NOT_ALIVE = 1


class ComposeLine:
    """The merged compose services, each with its container's files under ``folder``."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.certs = folder / "certs"
        make_compose_certs(self.certs)
        recordings = folder / "recordings"
        recordings.mkdir()
        env = {"BOLTWATCH_CERTS": str(self.certs), "BOLTWATCH_RECORDINGS": str(recordings)}
        self.services: dict[str, Any] = load_merged([BASE_FILE, TLS_FILE], env)["services"]
        self.port = free_tcp_port()
        self.page_port = free_tcp_port()  # the dashboard's, instead of 0.0.0.0:8080
        self.opcua_port = free_tcp_port()  # the OPC UA server's, instead of 0.0.0.0:4840
        self.can_ports = {"43113": str(free_udp_port()), "43114": str(free_udp_port())}
        self.processes: dict[str, subprocess.Popen[bytes]] = {}
        self._containers: dict[tuple[str, str | None], ContainerFiles] = {}

    def files(self, name: str, identity: str | None = None) -> ContainerFiles:
        """Service ``name``'s container (with another identity mounted, if given)."""
        if (name, identity) not in self._containers:
            self._containers[name, identity] = self._lay_out(name, identity)
        return self._containers[name, identity]

    def _lay_out(self, name: str, identity: str | None) -> ContainerFiles:
        volumes = list(self.services[name]["volumes"])
        if identity is not None:
            volumes = [v for v in volumes if split_volume(v)[1] != IDENTITY]
            volumes.append(f"{self.certs / identity}:{IDENTITY}:ro")
        root = self.folder / "containers" / (name if identity is None else f"{name}-as-{identity}")
        files = ContainerFiles(root, volumes)
        for station_file in files.host(TLS_STATIONS).glob("*.toml"):
            text = station_file.read_text().replace("tls/router:7447", f"tls/127.0.0.1:{self.port}")
            for compose_port, free_port in self.can_ports.items():
                text = re.sub(rf"^port = {compose_port}$", f"port = {free_port}", text, flags=re.M)
            station_file.write_text(text)
        return files

    def start(self, name: str) -> None:
        command = self.files(name).arguments(self.services[name]["command"])
        command = [a.replace("tls/0.0.0.0:7447", f"tls/127.0.0.1:{self.port}") for a in command]
        command = [a.replace("0.0.0.0:8080", f"127.0.0.1:{self.page_port}") for a in command]
        command = [a.replace("0.0.0.0:4840", f"127.0.0.1:{self.opcua_port}") for a in command]
        assert command[0] == "serve"
        self.processes[name] = serve(command[1:], self.folder / f"{name}.log")

    def health(self, name: str, service: str | None = None) -> subprocess.CompletedProcess[str]:
        """The container's health check (``CMD boltwatch health ...``), once; with
        ``service``, the same check in that container for another service."""
        test = self.services[name]["healthcheck"]["test"]
        assert test[:3] == ["CMD", "boltwatch", "health"]
        arguments = self.files(name).arguments(test[2:])
        if service is not None:
            arguments[1] = service
        return boltwatch(*arguments)

    def wait_healthy(self, names: Sequence[str], within_s: float) -> None:
        """Each of ``names`` healthy in turn, as compose waits on health before it counts a
        service up; AssertionError (with its log) when one fails its check, exits or is not
        healthy within ``within_s`` of the call."""
        deadline = time.monotonic() + within_s
        for name in names:
            while (checked := self.health(name)).returncode != 0:
                said = f"{checked.stdout}{checked.stderr}"
                assert checked.returncode == NOT_ALIVE, f"{name}'s health check failed: {said}"
                exited = self.processes[name].poll()
                assert exited is None, f"{name} exited ({exited}):\n{self.log(name)}"
                assert time.monotonic() < deadline, (
                    f"{name} never healthy: {said}\n{self.log(name)}"
                )
                time.sleep(0.5)

    def session(self, name: str, identity: str | None = None) -> zenoh.Session:
        """A session as service ``name``'s container opens it (its station file's [zenoh])."""
        files = self.files(name, identity)
        station_file = files.host(f"{TLS_STATIONS}/station1.toml")
        return open_session(load_station(station_file).config.zenoh)

    def log(self, name: str) -> str:
        return (self.folder / f"{name}.log").read_text(errors="replace")[-3000:]


@contextlib.contextmanager
def running_line(folder: Path, names: Sequence[str]) -> Iterator[ComposeLine]:
    """The compose line in ``folder`` with the services ``names`` started in that order, each
    stopped (SIGTERM, then SIGKILL after 10 s) in the reverse order at the end."""
    started = ComposeLine(folder)
    try:
        for name in names:
            started.start(name)
        yield started
    finally:
        for name in reversed(list(started.processes)):
            stop_process(started.processes[name], grace_s=10.0)
