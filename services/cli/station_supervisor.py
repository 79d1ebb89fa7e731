"""Start, watch and stop the processes of a station or a line (what ``boltwatch up`` runs).

Each service runs as ``python -m services.cli serve <name> --config FILE...`` in
its own session (so a terminal Ctrl-C reaches only the supervisor, which then
stops the services in order: the tool first, the recorder last, so that the
recording holds everything). Each service logs to its own file. Processes
that can stop at the same time (the rigs of a line, its acquisitions) are
stopped as a group: signalled together, then waited for. Should the supervisor
itself be killed outright, each service gets SIGTERM from the kernel
(:mod:`shared.runtime.supervisor_link`) and stops as it would on Ctrl-C.
"""

from __future__ import annotations

import logging
import os
import signal
import subprocess
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from shared.runtime import supervisor_environment

LOG = logging.getLogger(__name__)

STOP_GRACE_S = 8.0


def stop_process(process: subprocess.Popen[Any], grace_s: float = STOP_GRACE_S) -> int | None:
    """SIGTERM, wait up to ``grace_s``, then SIGKILL; returns the exit code."""
    if process.poll() is None:
        process.send_signal(signal.SIGTERM)
        try:
            process.wait(grace_s)
        except subprocess.TimeoutExpired:
            LOG.warning("pid %d did not stop within %.0f s: killed", process.pid, grace_s)
            process.kill()
            process.wait()
    return process.poll()


@dataclass
class ManagedProcess:
    name: str
    process: subprocess.Popen[bytes]
    log_path: Path

    @property
    def pid(self) -> int:
        return self.process.pid

    def exit_code(self) -> int | None:
        return self.process.poll()

    def log_tail(self, lines: int = 12) -> str:
        try:
            text = self.log_path.read_text(errors="replace")
        except OSError:
            return "(no log)"
        return "\n".join(text.splitlines()[-lines:])


def stop_processes(
    processes: Sequence[subprocess.Popen[Any]], grace_s: float = STOP_GRACE_S
) -> None:
    """SIGTERM to every process at once, wait up to ``grace_s`` for all, then SIGKILL the rest."""
    for process in processes:
        if process.poll() is None:
            process.send_signal(signal.SIGTERM)
    deadline = time.monotonic() + grace_s
    for process in processes:
        try:
            process.wait(max(0.0, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            LOG.warning("pid %d did not stop within %.0f s: killed", process.pid, grace_s)
            process.kill()
            process.wait()


class StationSupervisor:
    """The child processes of a station (or of a line of stations), in start order."""

    def __init__(self, config_path: Path | Sequence[Path], log_dir: Path) -> None:
        #: the station file(s) a service gets unless ``start`` names others
        self.config_paths = [config_path] if isinstance(config_path, Path) else list(config_path)
        self.log_dir = log_dir
        self.processes: list[ManagedProcess] = []
        log_dir.mkdir(parents=True, exist_ok=True)

    @property
    def config_path(self) -> Path:
        return self.config_paths[0]

    def start(
        self,
        service: str,
        extra_args: Sequence[str] = (),
        name: str | None = None,
        config_paths: Sequence[Path] | None = None,
    ) -> ManagedProcess:
        """Start ``boltwatch serve <service>``; its output goes to ``<log_dir>/<name>.log``.

        ``config_paths``: the station file(s) of this process (default: the supervisor's).
        """
        name = name or service
        command = [sys.executable, "-m", "services.cli", "serve", service]
        if service != "router":
            command += ["--config", *(str(p) for p in (config_paths or self.config_paths))]
        command += list(extra_args)
        log_path = self.log_dir / f"{name}.log"
        with log_path.open("wb") as log:
            process = subprocess.Popen(
                command,
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=subprocess.STDOUT,
                start_new_session=True,
                env={**os.environ, "PYTHONUNBUFFERED": "1", **supervisor_environment()},
            )
        managed = ManagedProcess(name, process, log_path)
        self.processes.append(managed)
        LOG.debug("started %s (pid %d)", name, process.pid)
        return managed

    def find(self, name: str) -> ManagedProcess:
        for managed in self.processes:
            if managed.name == name:
                return managed
        raise KeyError(name)

    def unexpected_exits(self, expected: set[str]) -> list[ManagedProcess]:
        """Processes that ended although they were not expected to."""
        return [p for p in self.processes if p.name not in expected and p.exit_code() is not None]

    def stop(self, managed: ManagedProcess, grace_s: float = STOP_GRACE_S) -> int | None:
        """Stop one process (see :func:`stop_process`); returns the exit code."""
        return stop_process(managed.process, grace_s)

    def stop_all(self, order: Sequence[str | Sequence[str]] | None = None) -> None:
        """Stop every process: those named in ``order`` first, in that order (a group of
        names stops together), then the rest in reverse start order."""
        remaining = list(reversed(self.processes))
        for step in order or ():
            names = {step} if isinstance(step, str) else set(step)
            group = [p for p in remaining if p.name in names]
            stop_processes([p.process for p in group])
            for managed in group:
                remaining.remove(managed)
        for managed in remaining:
            self.stop(managed)
