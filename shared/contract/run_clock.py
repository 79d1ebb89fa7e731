"""A run's clock: nanoseconds since the epoch <-> seconds since the run started.

Messages carry ``time_ns`` (int, ns since the Unix epoch); the predictor core,
events, decisions and plots count a run's seconds from its start (``time_s``).
One conversion, both ways, so every place agrees to the nanosecond::

    clock = RunClock(started_ns)
    clock.seconds(sample.time_ns)    # (time_ns - started_ns) / 1e9
    clock.ns(event.time_s)           # started_ns + round(time_s · 1e9)

``started_ns`` is the clock's zero: a run's start (``ToolState`` running), or
the date a controller file counts its times from.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class RunClock:
    """The clock of one run, zero at ``started_ns``."""

    started_ns: int

    def seconds(self, time_ns: int) -> float:
        """Seconds since the start of the run at epoch time ``time_ns``."""
        return (time_ns - self.started_ns) / 1e9

    def ns(self, time_s: float) -> int:
        """Epoch nanoseconds of run time ``time_s`` (rounded to the nearest ns)."""
        return self.started_ns + round(time_s * 1e9)

    def seconds_of(self, times_ns: Iterable[int]) -> list[float]:
        """:meth:`seconds` of each."""
        started_ns = self.started_ns
        return [(time_ns - started_ns) / 1e9 for time_ns in times_ns]

    def ns_of(self, times_s: Iterable[float]) -> list[int]:
        """:meth:`ns` of each."""
        started_ns = self.started_ns
        return [started_ns + round(time_s * 1e9) for time_s in times_s]
