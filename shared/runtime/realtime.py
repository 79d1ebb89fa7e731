"""Real-time scheduling for the threads a stop depends on (the station's CAN threads).

On a loaded edge box the kernel's fair scheduler lets a thread that just
received a frame wait behind whatever else runs: milliseconds, the length of
a stick phase. ``SCHED_FIFO`` runs it as soon as it is runnable. Measured on
the project's 2-core VM (a Python thread echoing a CAN frame over
udp_multicast at 1 kHz, quiet machine): p50 0.09 / p90 0.14 / p99 0.55 ms at
normal priority, 0.06 / 0.11 / 0.15 ms under ``SCHED_FIFO``.

A thread of a Python process also needs the GIL: another thread holding it
keeps a woken real-time thread waiting up to the interpreter's switch
interval (5 ms by default), so a process with such a thread lowers it
(:data:`SWITCH_INTERVAL_S`).

Where real-time priority is refused (not root, no ``CAP_SYS_NICE``, a
container without it, ``RLIMIT_RTPRIO`` of 0) the thread runs at normal
priority and says so once: the station works, with the latency of a loaded
box. ``BOLTWATCH_REALTIME=0`` in the environment turns it off.
"""

from __future__ import annotations

import logging
import os
import sys
import threading

LOG = logging.getLogger(__name__)

#: SCHED_FIFO priorities: the tool (the simulated rig, the reference a stop is
#: measured against) above the acquisition's CAN thread; both under 50, the
#: priority of the kernel's threaded interrupt handlers (the CAN controller's,
#: the NIC's), which must run first for a frame to arrive at all.
RIG_PRIORITY = 40
STOP_PATH_PRIORITY = 30
#: the GIL switch interval of a process with a real-time thread (default 5 ms)
SWITCH_INTERVAL_S = 0.0005
ENVIRONMENT_SWITCH = "BOLTWATCH_REALTIME"


def use_realtime_priority(priority: int, what: str) -> bool:
    """Run the calling thread under ``SCHED_FIFO`` at ``priority``; False (said once) if refused."""
    if os.environ.get(ENVIRONMENT_SWITCH, "1") == "0":
        LOG.info("%s: real-time priority off (%s=0)", what, ENVIRONMENT_SWITCH)
        return False
    sys.setswitchinterval(min(sys.getswitchinterval(), SWITCH_INTERVAL_S))
    try:
        os.sched_setscheduler(threading.get_native_id(), os.SCHED_FIFO, os.sched_param(priority))
    except (PermissionError, OSError, AttributeError) as err:
        LOG.warning(
            "%s: real-time priority refused (%s); running at normal priority, so stops on a "
            "loaded machine come later (docs/how-to/real-can-station.md, Real time)",
            what,
            getattr(err, "strerror", None) or err,
        )
        return False
    LOG.info("%s: SCHED_FIFO priority %d", what, priority)
    return True
