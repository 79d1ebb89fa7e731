"""The end of a service's process once everything is stopped and closed: without the
interpreter's finalisation.

During finalisation a native thread that calls into Python late (a zenoh
callback in flight as the session closed) is ended by ``pthread_exit``,
whose unwinding through native frames aborts the process ("FATAL: exception
not rethrown", SIGABRT): a clean stop would end with status -6 now and then
(seen once in about ten stops of the line's page after hostile clients, and once
in about eight of the OPC UA server with clients).
Nothing is left to run at exit by then: the logs and standard streams are
flushed first.
"""

from __future__ import annotations

import contextlib
import logging
import os
import sys
from typing import NoReturn


def exit_now(status: int) -> NoReturn:
    """End the process with ``status`` at once, logs and standard streams flushed."""
    logging.shutdown()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError, AttributeError):
            stream.flush()
    os._exit(status)
