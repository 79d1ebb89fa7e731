"""A service that ``boltwatch up`` started stops when ``up`` dies, whatever killed it.

``up`` starts each service in a session of its own (so a Ctrl-C reaches only
``up``, which then stops the services in order). Were ``up`` killed outright
(SIGKILL, the out-of-memory killer, a crash), its services would run on as
orphans: holding the CAN bus and the ports, recording, looking alive on the
line with nobody to stop them. ``up`` names itself in ``BOLTWATCH_SUPERVISOR_PID``;
a service started so asks the Linux kernel for a SIGTERM the moment its parent
dies (``prctl(PR_SET_PDEATHSIG)``), which stops it as ``up`` would have: files
closed, nothing lost. A service started by hand (no variable) is left alone.
"""

from __future__ import annotations

import ctypes
import logging
import os
import signal
from collections.abc import Mapping

from shared.errors import BoltwatchError

LOG = logging.getLogger(__name__)

SUPERVISOR_PID_ENV = "BOLTWATCH_SUPERVISOR_PID"
_PR_SET_PDEATHSIG = 1  # <linux/prctl.h>


class SupervisorGoneError(BoltwatchError):
    """The supervisor that started this process ended before the process could follow it."""


def supervisor_environment(supervisor_pid: int | None = None) -> dict[str, str]:
    """The variable a supervisor sets for the services it starts (default: this process)."""
    return {SUPERVISOR_PID_ENV: str(os.getpid() if supervisor_pid is None else supervisor_pid)}


def follow_supervisor(environ: Mapping[str, str] = os.environ) -> int | None:
    """Ask for SIGTERM when the parent dies, if ``environ`` names a supervisor; returns
    its pid (None when started by hand).

    Raises SupervisorGoneError when the parent is no longer that supervisor: it died
    between starting this process and this call, so no signal would ever come.
    """
    text = environ.get(SUPERVISOR_PID_ENV)
    if not text:
        return None
    try:
        supervisor_pid = int(text)
    except ValueError:
        LOG.warning("%s=%r is no process id: not following a supervisor", SUPERVISOR_PID_ENV, text)
        return None
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        failed = libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGTERM), 0, 0, 0) != 0
    except (AttributeError, OSError):  # not Linux
        failed = True
    if failed:
        LOG.warning(
            "cannot ask to be stopped when boltwatch up (pid %d) dies: if it is killed "
            "outright, stop this process by hand",
            supervisor_pid,
        )
    if os.getppid() != supervisor_pid:
        raise SupervisorGoneError(
            f"boltwatch up (pid {supervisor_pid}) that started this service has ended"
        )
    return supervisor_pid
