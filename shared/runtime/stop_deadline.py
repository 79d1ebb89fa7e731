"""A service's stop has a deadline: past it the process leaves, saying where it was stuck.

A service that hangs while it stops (a thread that never ends, a close that
waits for a peer that is gone) would keep its CAN bus, its ports and its
health token's name for ever, and ``up`` or a container runtime would wait
for it. :class:`StopDeadline` is armed when a service's work has ended and
its stop stages begin (:meth:`~shared.runtime.service_skeleton.ServiceSkeleton.run`)
and disarmed when they are done; if they take longer than
:data:`STOP_DEADLINE_S`, it logs one line, writes every thread's stack to
stderr (the service's log) and ends the process with exit status 1.

Every service also writes every thread's stack to stderr on SIGUSR1
(``kill -USR1 <pid>``), without stopping: what a person asks of a service
that seems stuck.
"""

from __future__ import annotations

import faulthandler
import logging
import os
import signal
import sys
import threading

LOG = logging.getLogger(__name__)

#: how long a service's stop stages may take (they take well under a second when healthy)
STOP_DEADLINE_S = 20.0
#: the exit status of a process that left at its deadline
DEADLINE_EXIT_STATUS = 1


def dump_stacks_on_sigusr1() -> None:
    """Every thread's stack to stderr on SIGUSR1 (the process goes on)."""
    faulthandler.register(signal.SIGUSR1, file=sys.stderr, all_threads=True)


class StopDeadline:
    """Leave the process ``deadline_s`` from now unless :meth:`disarm` comes first."""

    def __init__(self, name: str, deadline_s: float = STOP_DEADLINE_S) -> None:
        self.name = name
        self.deadline_s = deadline_s
        self._disarmed = threading.Event()
        threading.Thread(target=self._watch, name="stop-deadline", daemon=True).start()

    def disarm(self) -> None:
        self._disarmed.set()

    def _watch(self) -> None:
        if self._disarmed.wait(self.deadline_s):
            return
        LOG.critical(
            "%s: its stop took more than %.0f s; leaving now (every thread's stack follows)",
            self.name,
            self.deadline_s,
        )
        for handler in logging.getLogger().handlers:
            handler.flush()
        faulthandler.dump_traceback(file=sys.stderr, all_threads=True)
        sys.stderr.flush()
        os._exit(DEADLINE_EXIT_STATUS)
