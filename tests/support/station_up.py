"""``boltwatch up`` as a test runs it: to its end, or started and watched; recordings read."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

from mcap.reader import make_reader

from tests.support.paths import REPO
from tests.support.station_files import (
    child_pids,
    command_line,
)

UP_TIMEOUT_S = 150


def up_command(station: Path, runs: int) -> list[str]:
    return [
        sys.executable,
        "-m",
        "services.cli",
        "up",
        "--config",
        str(station),
        "--runs",
        str(runs),
    ]


def run_up(
    station: Path, runs: int, *options: str, status: int = 0
) -> subprocess.CompletedProcess[str]:
    """``boltwatch up`` to its end; it must exit with ``status`` (its output is the failure's
    message)."""
    result = subprocess.run(
        [*up_command(station, runs), *options],
        capture_output=True,
        text=True,
        timeout=UP_TIMEOUT_S,
        cwd=REPO,
        check=False,
    )
    assert result.returncode == status, result.stdout + result.stderr
    return result


def read_recordings(folder: Path) -> dict[str, list[dict[str, Any]]]:
    """Every message of every MCAP file under ``folder``, by topic, decoded with json only."""
    by_topic: dict[str, list[dict[str, Any]]] = defaultdict(list)
    files = sorted(folder.rglob("*.mcap"))
    assert files, f"no MCAP files under {folder}"
    for path in files:
        with path.open("rb") as handle:
            for schema, channel, message in make_reader(handle).iter_messages():
                assert schema is not None and schema.encoding == "jsonschema"
                assert channel.message_encoding == "json"
                by_topic[channel.topic].append(json.loads(message.data))
    return by_topic


def start_up(station: Path, runs: int) -> subprocess.Popen[str]:
    """``up`` as from a terminal: SIGINT (Ctrl-C) at its default, even when the suite itself
    was started in the background (a shell without job control starts what it puts behind
    ``&`` with SIGINT ignored, and a child keeps an ignored signal ignored; a handled one is
    at its default after exec, so one is handled here while ``up`` starts)."""
    handled = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        return subprocess.Popen(
            up_command(station, runs),
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            cwd=REPO,
        )
    finally:
        signal.signal(signal.SIGINT, handled)


def wait_for_first_run(up: subprocess.Popen[str]) -> str:
    """Read ``up``'s output until the first table row (a line starting with a run id)."""
    assert up.stdout is not None
    seen = ""
    deadline = time.monotonic() + UP_TIMEOUT_S
    while time.monotonic() < deadline:
        line = up.stdout.readline()
        if not line:
            break
        seen += line
        if line.strip()[:1].isdigit() and "kN" in line:
            return seen
    up.kill()
    raise AssertionError(f"no run finished; output so far:\n{seen}")


def services_of(up: subprocess.Popen[str]) -> dict[str, int]:
    found = {}
    for pid in child_pids(up.pid):
        words = command_line(pid).split()
        if "serve" in words:
            found[words[words.index("serve") + 1]] = pid
    return found


def wear_ledger_rows(wear_text: str, tool_id: int) -> list[list[str]]:
    """The rows of ``tool_id`` in the ledger's table, the first of ``boltwatch wear``'s text
    (the service forecast's table below it has a row per tool too)."""
    ledger, _, _ = wear_text.partition("\n\n")
    return [row.split() for row in ledger.splitlines() if row.split()[:1] == [str(tool_id)]]
