"""Running sums of force so that the plateau between any two recent samples is O(1).

A stick phase holds the preload still (eq. 9: the screw does not turn), so
the plateau F_j is the mean force over the stick phase. The history keeps
the cumulative force sum per sample index in a ring of :data:`CAPACITY`
samples (4 s at 1 kHz, far longer than one stick phase), so the mean over
samples a..b is (C_b - C_(a-1)) / (b - a + 1) at any time, per event.
"""

from __future__ import annotations

import math

CAPACITY = 4096


class ForceHistory:
    """Cumulative force per accepted sample index."""

    def __init__(self) -> None:
        self._cumulative = [0.0] * CAPACITY
        self._total = 0.0
        self.count = 0  # samples added; the newest has index count - 1

    def add(self, force_n: float) -> None:
        """Append the force of the next sample (NaN adds nothing usable)."""
        if not math.isnan(force_n):
            self._total += force_n
        else:
            self._total = math.nan
        self._cumulative[self.count % CAPACITY] = self._total
        self.count += 1

    def mean(self, first: int, last: int) -> float:
        """Mean force over sample indices first..last (clamped to what is kept); NaN if none."""
        last = min(last, self.count - 1)
        first = max(first, self.count - CAPACITY + 1, 0)
        if last < first:
            return math.nan
        before = self._cumulative[(first - 1) % CAPACITY] if first > 0 else 0.0
        return (self._cumulative[last % CAPACITY] - before) / (last - first + 1)

    def plateau_before(self, trough_index: int, peak_index: int) -> float:
        """F_j: mean over the second half of the stick phase trough_(j-1) .. peak_j.

        The first half is left out: the slip before it may still ring.
        """
        start = trough_index + 1 + max(0, (peak_index - trough_index) // 2)
        return self.mean(min(start, peak_index), peak_index)

    def plateau_after(self, trough_index: int) -> float:
        """The plateau the joint sits on now, after the slip that ended at ``trough_index``."""
        newest = self.count - 1
        first = trough_index + 1 if newest > trough_index + 1 else trough_index
        return self.mean(first, newest)
