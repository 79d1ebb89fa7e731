"""The noise of a signal as the running median of its |second difference|, O(1) per sample.

For a signal that is locally a straight line (a stick ramp, a motor turning
at constant speed) the second difference d2 = x_i - 2 x_(i-1) + x_(i-2) is
noise only: for white noise of σ, d2 has the spread √6 σ and the median of
|d2| is 0.674 · √6 σ ≈ 1.65 σ. A median, not a mean: the kinks of a slip are
a small share of the samples and barely lift it.

The estimate moves by multiplicative steps of ±:data:`STEP` per sample
(the median of a stream, without keeping it). It starts from the exact
(upper) median of the first :data:`SEED_SAMPLES` values, not from one: a
single |d2| can lie anywhere from 0 to several σ, and at 2 % per sample a
start 25 times too low (seed 1, joint 80 of the accuracy benchmark: 0.013 Nm
against 0.33 Nm) took about 400 samples to climb out, while the wiggles of a
slow stick ramp passed as slips. Until SEED_SAMPLES values exist the
estimate is the (upper) median of those seen so far.
"""

from __future__ import annotations

import bisect
import math

STEP = 0.02
SEED_SAMPLES = 32  # |d2| values whose median starts the running estimate
FLOOR = 1e-12  # the estimate never reaches 0, so a multiplicative step can grow it again


class SecondDifferenceNoise:
    """Feed a signal sample by sample; :attr:`median` is the running median of |d2|."""

    def __init__(self) -> None:
        self.median = 0.0
        self._x1 = math.nan
        self._x2 = math.nan
        self._seed: list[float] = []  # the first SEED_SAMPLES |d2|, then unused
        self.seeded = False  # SEED_SAMPLES values seen: the estimate is a running one now

    def add(self, value: float) -> None:
        """Update the estimate with the newest sample (finite: the input guard saw to it)."""
        x1 = self._x1
        if not (math.isnan(x1) or math.isnan(self._x2)):  # both seen
            d2 = abs(value - 2.0 * x1 + self._x2)
            if not self.seeded:
                self._add_seed(d2)
            elif d2 > self.median:
                self.median *= 1.0 + STEP
            else:
                self.median *= 1.0 - STEP
        self._x2 = x1
        self._x1 = value

    def _add_seed(self, d2: float) -> None:
        values = self._seed
        bisect.insort(values, d2)
        self.median = max(values[len(values) // 2], FLOOR)
        if len(values) >= SEED_SAMPLES:
            self.seeded = True
            values.clear()
