"""A service started by ``boltwatch up`` follows it: a SIGTERM when ``up`` dies, and a
clear refusal to start when ``up`` is already gone (no signal would ever come)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

from shared.runtime import SUPERVISOR_PID_ENV
from tests.support.paths import REPO

FOLLOWER = """
import signal, sys, time
from shared.runtime.supervisor_link import follow_supervisor
signal.signal(signal.SIGTERM, lambda *_: sys.exit(15))
follow_supervisor()
print("following", flush=True)
time.sleep(60)
"""

SUPERVISOR = """
import os, subprocess, sys, time
from shared.runtime.supervisor_link import supervisor_environment
child = subprocess.Popen([sys.executable, "-c", sys.argv[1]],
                         env={**os.environ, **supervisor_environment()}, start_new_session=True)
print(child.pid, flush=True)
time.sleep(60)
"""


def test_the_follower_gets_sigterm_when_its_supervisor_is_killed() -> None:
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    supervisor = subprocess.Popen(
        [sys.executable, "-c", SUPERVISOR, FOLLOWER], stdout=subprocess.PIPE, text=True, env=env
    )
    assert supervisor.stdout is not None
    follower_pid = int(supervisor.stdout.readline())
    assert supervisor.stdout.readline() == "following\n"  # the follower shares the pipe
    supervisor.kill()
    supervisor.wait(10)
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        try:
            os.kill(follower_pid, 0)
        except ProcessLookupError:
            return
        time.sleep(0.05)
    os.kill(follower_pid, signal.SIGKILL)
    raise AssertionError("the follower outlived its supervisor")


def test_a_service_whose_supervisor_is_gone_refuses_to_start() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "services.cli", "serve", "router", "--listen", "tcp/127.0.0.1:1"],
        env={**os.environ, "PYTHONPATH": str(REPO), SUPERVISOR_PID_ENV: "1"},
        check=False,
        capture_output=True,
        text=True,
        timeout=60,
        cwd=REPO,
    )
    assert result.returncode == 2
    assert "boltwatch serve router: boltwatch up (pid 1) that started this service has ended" in (
        result.stderr
    )
