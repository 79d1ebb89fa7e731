"""A service's stop that hangs ends the process at its deadline with every thread's stack
in its log; one that ends in time is left alone; SIGUSR1 writes the stacks and goes on.
Real processes (the deadline ends the process it is in)."""

from __future__ import annotations

import signal
import subprocess
import sys

from tests.support.paths import REPO

HANGING = """
import logging, threading, time
from shared.runtime.stop_deadline import StopDeadline
logging.basicConfig(level=logging.INFO)
deadline = StopDeadline("acquisition", 1.0)
threading.Event().wait({wait_s})  # a stop stage that waits for a peer that is gone
deadline.disarm()
print("stopped in time")
"""


def _run(wait_s: float) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", HANGING.format(wait_s=wait_s)],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )


def test_a_stop_past_its_deadline_leaves_with_every_threads_stack() -> None:
    ended = _run(wait_s=30.0)
    assert ended.returncode == 1, ended.stderr
    assert "acquisition: its stop took more than 1 s; leaving now" in ended.stderr
    assert "Thread 0x" in ended.stderr and "in wait" in ended.stderr, ended.stderr
    assert "stopped in time" not in ended.stdout


def test_a_stop_in_time_is_left_alone() -> None:
    ended = _run(wait_s=0.05)
    assert (ended.returncode, ended.stdout) == (0, "stopped in time\n"), ended.stderr


def test_sigusr1_writes_the_stacks_and_the_service_goes_on() -> None:
    script = (
        "import sys, time\n"
        "from shared.runtime.stop_deadline import dump_stacks_on_sigusr1\n"
        "dump_stacks_on_sigusr1()\n"
        "print('ready', flush=True)\n"
        "time.sleep(2)\n"
        "print('went on', flush=True)\n"
    )
    process = subprocess.Popen(
        [sys.executable, "-c", script],
        cwd=REPO,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert process.stdout is not None and process.stdout.readline() == "ready\n"
    process.send_signal(signal.SIGUSR1)
    out, err = process.communicate(timeout=30)
    assert process.returncode == 0 and out == "went on\n", err
    assert "Current thread" in err and "in <module>" in err, err
