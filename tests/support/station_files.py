"""Isolated station files for system tests: own zenoh port, own CAN multicast port,
own recordings folder, so tests never see each other's (or a running station's) traffic."""

from __future__ import annotations

import contextlib
import os
import re
import signal
import subprocess
import sys
from pathlib import Path

from tests.support.free_ports import free_tcp_port, free_udp_port
from tests.support.paths import CONFIG, REPO, STATION_FILE


def write_station(
    folder: Path,
    *,
    zenoh_port: int | None = None,
    zenoh_mode: str = "client",
    replacements: dict[str, str] | None = None,
    placement: str | None = None,
) -> Path:
    """A copy of config/station.toml isolated for one test; returns its path.

    ``zenoh_mode="peer"`` makes the services listen on nothing and connect to
    ``zenoh_port`` (where the test runs its own router or peer session).
    ``placement``: the ``[predictor] placement`` ("line": a separate predictor
    process decides over zenoh; default: the shipped file's, the edge).
    """
    zenoh_port = zenoh_port or free_tcp_port()
    text = STATION_FILE.read_text()
    text = text.replace('"joints/', f'"{CONFIG}/joints/').replace('"can/', f'"{CONFIG}/can/')
    text = re.sub(r"^port = \d+", f"port = {free_udp_port()}", text, flags=re.MULTILINE)
    text = text.replace('mode = "client"', f'mode = "{zenoh_mode}"')
    text = text.replace("tcp/127.0.0.1:7447", f"tcp/127.0.0.1:{zenoh_port}")
    text = text.replace('folder = "../recordings"', f'folder = "{folder / "recordings"}"')
    if placement is not None:
        text = text.replace("[predictor]\n", f'[predictor]\nplacement = "{placement}"\n', 1)
    for old, new in (replacements or {}).items():
        if old not in text:
            raise AssertionError(f"station template has no {old!r}")
        text = text.replace(old, new)
    path = folder / "station.toml"
    path.write_text(text)
    return path


def serve(args: list[str], log: Path, repo: Path | None = None) -> subprocess.Popen[bytes]:
    """``python -m services.cli serve ARGS`` from the repository, output appended to ``log``;
    ``repo``: from that checkout instead, its code first on the path (a benchmark of another
    commit)."""
    with log.open("ab") as out:
        return subprocess.Popen(
            [sys.executable, "-m", "services.cli", "serve", *args],
            cwd=repo or REPO,
            env=None if repo is None else {**os.environ, "PYTHONPATH": str(repo)},
            stdout=out,
            stderr=subprocess.STDOUT,
        )


def child_pids(pid: int) -> list[int]:
    """Direct children of ``pid`` (Linux /proc)."""
    try:
        text = Path(f"/proc/{pid}/task/{pid}/children").read_text()
    except OSError:
        return []
    return [int(p) for p in text.split()]


def command_line(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()
    except OSError:
        return ""


def is_running(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    status = Path(f"/proc/{pid}/status")
    try:
        return "State:\tZ" not in status.read_text()
    except OSError:
        return False


def process_report(pid: int) -> str:
    """What a process is doing, for an assertion message: its command line, state, and
    each thread's name, state and kernel wait channel (Linux /proc)."""
    lines = [f"{pid}: {command_line(pid)[:200]}"]
    with contextlib.suppress(OSError):
        for task in sorted(Path(f"/proc/{pid}/task").iterdir()):
            with contextlib.suppress(OSError):
                status = dict(
                    line.split(":\t", 1)
                    for line in (task / "status").read_text().splitlines()
                    if ":\t" in line
                )
                wchan = (task / "wchan").read_text()
                lines.append(
                    f"  {task.name} {status.get('Name', '?')}: {status.get('State', '?')} {wchan}"
                )
    return "\n".join(lines)


def kill_all(pids: list[int]) -> None:
    for pid in pids:
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGKILL)
