"""Where a steadily rising signal will be when the motor has actually stopped. O(1) per sample.

A stop is not instantaneous: the controller halts the motor some samples
after the sample that decided it (the station's reaction, ``reaction_samples``).
On a joint that slides smoothly (no stick phase: the screw never stops, so
there is no plateau to choose) the force, and the torque, keep rising at the
rate r per sample all that time, so waiting for the measured value to reach
the target overshoots by about r · (reaction + 1/2) on average.

The estimator keeps the running sum of the signal in a ring and compares
block means of BLOCK samples:

    r_short = (mean[k-3..k] - mean[k-7..k-4]) / BLOCK
    r_long  = (mean[k-3..k] - mean[k-11..k-8]) / (2 BLOCK)

The ramp is *steady* when both are positive and agree within STEADY_BAND:
a stick-slip trace (flat stick, a jump per slip) fails this whenever a slip
is within the last 12 samples, and a flat one is not rising. On a steady
ramp the value now is mean[k-3..k] + r · (BLOCK - 1)/2 (the block mean lags
by 1.5 samples), and the value the motor stops at, the best place to stop
being the first sample whose successor would be further past the target, is

    projected = now + r · (reaction + 1/2)

Means of four samples also keep one noise spike from deciding.
"""

from __future__ import annotations

import math

BLOCK = 4
SPAN = 3 * BLOCK
STEADY_BAND = (0.6, 1.6)  # r_short / r_long of a steady ramp


class RampEstimator:
    """Running block means of one signal; :meth:`projected` on a steady ramp, else NaN."""

    def __init__(self) -> None:
        self._cumulative = [0.0] * (SPAN + 1)
        self._total = 0.0
        self.count = 0

    def add(self, value: float) -> None:
        """The next sample (NaN makes the next SPAN samples unusable)."""
        self._total += value
        if math.isnan(self._total):
            self._total = 0.0
            self.count = -SPAN  # start over once the bad sample has left
        self.count += 1
        self._cumulative[self.count % (SPAN + 1)] = self._total

    def _block_sum(self, back: int) -> float:
        """Sum of the BLOCK samples ending ``back`` samples before the newest."""
        n = SPAN + 1
        end = self._cumulative[(self.count - back) % n]
        start = self._cumulative[(self.count - back - BLOCK) % n]
        return end - start

    def projected(self, lead_samples: float) -> float:
        """The value ``lead_samples`` after now on a steady ramp; NaN when not on one."""
        if self.count <= SPAN:
            return math.nan
        newest = self._block_sum(0)
        short = (newest - self._block_sum(BLOCK)) / (BLOCK * BLOCK)
        long = (newest - self._block_sum(2 * BLOCK)) / (2 * BLOCK * BLOCK)
        if short <= 0.0 or long <= 0.0:
            return math.nan
        ratio = short / long
        if not STEADY_BAND[0] <= ratio <= STEADY_BAND[1]:
            return math.nan
        return newest / BLOCK + long * (0.5 * (BLOCK - 1) + lead_samples)
