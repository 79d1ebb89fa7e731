"""One log line for a flood of alike faults: the first at once, then at most one per interval.

A service refusing bad payloads counts every one; its log must not grow by a
line (or a traceback) per message when a faulty or hostile node floods a
key. :class:`RateLimitedLog` logs the first occurrence as it comes, then at
most one line per :data:`INTERVAL_S` with the newest occurrence and how many
were not logged since the last line. Safe to call from several threads.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from typing import Any

#: at most one line per this many seconds after the first
INTERVAL_S = 10.0


class RateLimitedLog:
    """Log ``message % args`` at ``level``: the first call, then at most once per interval."""

    def __init__(
        self,
        logger: logging.Logger,
        level: int = logging.WARNING,
        interval_s: float = INTERVAL_S,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._logger = logger
        self._level = level
        self._interval_s = interval_s
        self._clock = clock
        self._lock = threading.Lock()
        self._next_s: float | None = None
        self.suppressed = 0  # calls not logged since the last line

    def __call__(self, message: str, *args: Any) -> None:
        now = self._clock()
        with self._lock:
            if self._next_s is not None and now < self._next_s:
                self.suppressed += 1
                return
            first = self._next_s is None
            suppressed, self.suppressed = self.suppressed, 0
            self._next_s = now + self._interval_s
        if first:
            tail = f" (logged once, then at most every {self._interval_s:g} s)"
        else:
            tail = f" ({suppressed} more like it since the last line)"
        self._logger.log(self._level, message + tail, *args)
