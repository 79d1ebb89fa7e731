"""How a long-running boltwatch service lives and dies.

A service's work loop usually blocks in a zenoh ``recv()`` or a CAN
``recv()``. Python runs signal handlers only on the main thread between
bytecodes, so the loop runs in a worker thread; the main thread waits for
SIGINT/SIGTERM (or the worker's end), then sets the stop flag and calls the
service's ``wake`` (e.g. a session-local zenoh put that unblocks ``recv``).
An exception in the worker ends the service with exit status 1 and its
one-line message in the log.
"""

from __future__ import annotations

import logging
import signal
import threading
from collections.abc import Callable
from types import FrameType

from shared.errors import BoltwatchError

LOG = logging.getLogger(__name__)


class ServiceRunner:
    """Run ``work(stop)`` in a thread until it returns or a signal asks to stop."""

    def __init__(
        self,
        name: str,
        work: Callable[[threading.Event], None],
        wake: Callable[[], None] = lambda: None,
        grace_s: float = 5.0,
    ) -> None:
        self.name = name
        self._work = work
        self._wake = wake
        self._grace_s = grace_s
        self.stop = threading.Event()
        self._error: BaseException | None = None

    def _run_work(self) -> None:
        try:
            self._work(self.stop)
        except BaseException as err:  # reported by run(), never swallowed
            self._error = err
        finally:
            self.stop.set()

    def _on_signal(self, signum: int, _frame: FrameType | None) -> None:
        LOG.info("%s: %s received, stopping", self.name, signal.Signals(signum).name)
        self.stop.set()

    def run(self) -> int:
        """Block until the work ends; 0 on a clean end, 1 on an error in the work."""
        previous = {
            sig: signal.signal(sig, self._on_signal) for sig in (signal.SIGINT, signal.SIGTERM)
        }
        worker = threading.Thread(target=self._run_work, name=self.name, daemon=True)
        worker.start()
        try:
            while not self.stop.wait(0.1):
                pass
            if worker.is_alive():
                self._wake()
            worker.join(self._grace_s)
            if worker.is_alive():
                LOG.error("%s: work did not end within %.1f s", self.name, self._grace_s)
                return 1
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)
        if self._error is not None:
            if isinstance(self._error, BoltwatchError):
                LOG.error("%s: %s", self.name, self._error)
            else:
                LOG.error("%s failed", self.name, exc_info=self._error)
            return 1
        return 0
