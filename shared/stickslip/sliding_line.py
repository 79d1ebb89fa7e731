"""A least-squares line through the newest samples of a signal, O(1) per sample. Pure.

The final stage halts on a slow stick ramp whose rise per sample is a
fraction of the sensor's noise: one sample is no measure of where the torque
is, a line through the last n samples is. With the samples at x = 0 … n−1
(the newest at n−1) and the running sums S_y = Σ y_i and S_xy = Σ i · y_i::

    slope = (S_xy − x̄ S_y) / S_xx,   x̄ = (n − 1)/2,   S_xx = n (n² − 1)/12
    end   = S_y / n + slope · (n − 1)/2               (the line at the newest sample)

When the window is full the oldest sample leaves at x = 0 and the others
move one place down: S_xy loses the sum of the ones that stay. For white
noise of σ the end of the line has the spread 2σ/√n (n large), against σ
for the newest sample alone.
"""

from __future__ import annotations

import math
from collections import deque


class SlidingLine:
    """The line through the newest ``size`` samples (fewer until that many came)."""

    __slots__ = ("_sum_xy", "_sum_y", "_values", "size")

    def __init__(self, size: int) -> None:
        if size < 2:
            raise ValueError(f"a line needs at least 2 samples (got size {size})")
        self.size = size
        self._values: deque[float] = deque()
        self._sum_y = 0.0
        self._sum_xy = 0.0

    def __len__(self) -> int:
        return len(self._values)

    def clear(self) -> None:
        """Forget every sample (a slip, a new stage: the old line no longer holds)."""
        self._values.clear()
        self._sum_y = self._sum_xy = 0.0

    def add(self, value: float) -> None:
        """The newest sample."""
        values = self._values
        if len(values) == self.size:
            oldest = values.popleft()
            self._sum_y -= oldest
            self._sum_xy -= self._sum_y  # every remaining sample moves one place down
        self._sum_xy += len(values) * value
        self._sum_y += value
        values.append(value)

    @property
    def slope(self) -> float:
        """Rise per sample; NaN with fewer than 2 samples."""
        n = len(self._values)
        if n < 2:
            return math.nan
        mean_x = 0.5 * (n - 1)
        return (self._sum_xy - mean_x * self._sum_y) / (n * (n * n - 1) / 12.0)

    @property
    def end(self) -> float:
        """The line's value at the newest sample; NaN with fewer than 2 samples."""
        n = len(self._values)
        if n < 2:
            return math.nan
        return self._sum_y / n + self.slope * 0.5 * (n - 1)
