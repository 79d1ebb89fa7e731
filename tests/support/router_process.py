"""A router process for a test, and ``boltwatch`` run as a command (the way a person runs it)."""

from __future__ import annotations

import contextlib
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

from services.cli.station_supervisor import stop_process
from shared.errors import TransportError
from shared.runtime import open_from, zenoh_config
from tests.support.paths import REPO
from tests.support.station_files import free_tcp_port


def boltwatch(
    *args: str, timeout_s: float | None = 30, check: bool = False
) -> subprocess.CompletedProcess[str]:
    """``boltwatch ARGS`` run from the repository as a person runs it, its output as text;
    ``check``: CalledProcessError unless it exits 0."""
    return subprocess.run(
        [sys.executable, "-m", "services.cli", *args],
        capture_output=True,
        text=True,
        timeout=timeout_s,
        cwd=REPO,
        check=check,
    )


@contextlib.contextmanager
def router_process(tmp_path: Path, endpoint: str | None = None) -> Iterator[str]:
    """A ``boltwatch serve router`` process (on ``endpoint``; None: a free port); yields its
    endpoint once it accepts clients."""
    endpoint = endpoint or f"tcp/127.0.0.1:{free_tcp_port()}"
    log = (tmp_path / "router.log").open("w")
    process = subprocess.Popen(
        [sys.executable, "-m", "services.cli", "serve", "router", "--listen", endpoint],
        cwd=REPO,
        stdout=log,
        stderr=subprocess.STDOUT,
    )
    try:
        deadline = time.monotonic() + 20
        while True:
            assert process.poll() is None, (tmp_path / "router.log").read_text()
            try:
                open_from(zenoh_config("client", [endpoint], connect_timeout_ms=300)).close()
                break
            except TransportError:
                if time.monotonic() > deadline:
                    raise
        yield endpoint
    finally:
        stop_process(process, grace_s=10)
        log.close()
