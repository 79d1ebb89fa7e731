"""node-opcua's client (npm, pinned) as a process: :mod:`tests.support.opcua_client.js`.

:func:`node_opcua_client` installs ``node-opcua-client`` once into
``.cache/node-opcua-client/`` of the checkout (``npm install --prefix``) and
gives the folder, or the reason it cannot (no node or npm, the install failed:
the tests that need it skip with that reason). :func:`run_client` runs the
script with its options and gives its JSON lines.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path
from typing import Any

from tests.support.paths import REPO

PACKAGE = "node-opcua-client"
VERSION = "2.186.4"
CACHE = REPO / ".cache" / "node-opcua-client"
SCRIPT = Path(__file__).with_name("opcua_client.js")
INSTALL_TIMEOUT_S = 300


def node_opcua_client() -> tuple[Path | None, str]:
    """(the installed package's node_modules, "") or (None, why not)."""
    if shutil.which("node") is None or shutil.which("npm") is None:
        return None, "node and npm are needed for node-opcua's client"
    modules = CACHE / "node_modules"
    installed = modules / PACKAGE / "package.json"
    if installed.is_file() and json.loads(installed.read_text()).get("version") == VERSION:
        return modules, ""
    CACHE.mkdir(parents=True, exist_ok=True)
    done = subprocess.run(
        [
            "npm",
            "install",
            "--prefix",
            str(CACHE),
            "--no-audit",
            "--no-fund",
            "--silent",
            f"{PACKAGE}@{VERSION}",
        ],
        capture_output=True,
        text=True,
        timeout=INSTALL_TIMEOUT_S,
        check=False,
    )
    if done.returncode != 0 or not installed.is_file():
        reason = (done.stderr.strip().splitlines() or ["no output"])[-1]
        return None, f"npm could not install {PACKAGE}@{VERSION}: {reason}"
    return modules, ""


def start_client(modules: Path, options: dict[str, Any]) -> subprocess.Popen[str]:
    """The client process (its JSON lines on stdout, its stderr kept apart)."""
    return subprocess.Popen(
        ["node", str(SCRIPT), json.dumps(options)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "NODE_PATH": str(modules)},
    )


def lines_of(output: str) -> list[dict[str, Any]]:
    """The JSON lines of the client's output (other lines passed over)."""
    found = []
    for line in output.splitlines():
        if line.startswith("{"):
            found.append(json.loads(line))
    return found


def run_client(modules: Path, options: dict[str, Any], timeout_s: float) -> list[dict[str, Any]]:
    """Run the client to its end; its JSON lines (AssertionError with its output if it fails)."""
    client = start_client(modules, options)
    out, err = client.communicate(timeout=timeout_s)
    assert client.returncode == 0, f"node-opcua client failed:\n{out}\n{err}"
    return lines_of(out)
