"""Running sums of force so that the plateau between any two recent samples is O(1).

A stick phase holds the preload still (eq. 9: the screw does not turn), so
the plateau F_j is the mean force over the stick phase. The history keeps,
per sample index, the cumulative force sum and the cumulative number of
samples that had a force, in a ring of :data:`CAPACITY` samples (4 s at
1 kHz, far longer than one stick phase), so the mean over samples a..b is
(C_b - C_(a-1)) / (N_b - N_(a-1)) at any time, per event. A sample without a
force (before the run's first good one: see :mod:`.input_guard`) adds to
neither sum: the means are over the samples that had one, and a plateau
with none is None.
"""

from __future__ import annotations

CAPACITY = 4096


class ForceHistory:
    """Cumulative force and force count per accepted sample index."""

    def __init__(self) -> None:
        self._cumulative = [0.0] * CAPACITY
        self._counted = [0] * CAPACITY
        self._total = 0.0
        self._with_force = 0
        self.count = 0  # samples added; the newest has index count - 1

    def add(self, force_n: float | None) -> None:
        """Append the force of the next sample (None: it had none)."""
        if force_n is not None:
            self._total += force_n
            self._with_force += 1
        slot = self.count % CAPACITY
        self._cumulative[slot] = self._total
        self._counted[slot] = self._with_force
        self.count += 1

    def mean(self, first: int, last: int) -> float | None:
        """Mean force over sample indices first..last (clamped to what is kept); None if none."""
        last = min(last, self.count - 1)
        first = max(first, self.count - CAPACITY + 1, 0)
        if last < first:
            return None
        if first > 0:
            before = (first - 1) % CAPACITY
            total_before, counted_before = self._cumulative[before], self._counted[before]
        else:
            total_before, counted_before = 0.0, 0
        counted = self._counted[last % CAPACITY] - counted_before
        if counted == 0:
            return None
        return (self._cumulative[last % CAPACITY] - total_before) / counted

    def plateau_before(self, trough_index: int, peak_index: int) -> float | None:
        """F_j: mean over the second half of the stick phase trough_(j-1) .. peak_j.

        The first half is left out: the slip before it may still ring.
        """
        start = trough_index + 1 + max(0, (peak_index - trough_index) // 2)
        return self.mean(min(start, peak_index), peak_index)

    def plateau_after(self, trough_index: int) -> float | None:
        """The plateau the joint sits on now, after the slip that ended at ``trough_index``."""
        newest = self.count - 1
        first = trough_index + 1 if newest > trough_index + 1 else trough_index
        return self.mean(first, newest)
