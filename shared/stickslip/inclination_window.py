"""The window of the n newest samples and its mean inclination (paper eqs. 43-51).

D_T and D_t (eqs. 43, 45) are ring buffers of n samples, with the angle and
the sample's index beside them (the force of eq. 44 is kept per index by
:mod:`.force_history`: the plateaus need more than n samples of it). The inclination
sum S = Σ ΔT_i/Δt_i over the n-1 neighbouring pairs of the window (eq. 46)
is kept as a running sum: each new sample adds its slope and the pair that
leaves the window subtracts its own, so the work per sample is O(1). The sum
is recomputed exactly every :data:`RESUM_EVERY` samples to stop rounding drift.

Uneven Δt: each pair uses its own Δt, so a gap of tens of ms weighs its pair
lightly (a slow mean slope) rather than as a jump. A repeated timestamp
(Δt = 0) would divide by zero: Δt is clamped from below to half the nominal
period (:data:`MIN_DT_FRACTION`), which keeps the sign of that pair's slope
and gives it the weight of a normal pair.

M = S/|S| (eq. 47); M = 0 keeps the previous state. A change from +1 to -1
means a maximum has passed: T_max = max(D_T) at t_max (eqs. 48, 49); from
-1 to +1 a minimum: T_min = min(D_T) at t_min (eqs. 50, 51). Finding the
extreme is O(n) but happens once per flip, not per sample.
"""

from __future__ import annotations

MIN_DT_FRACTION = 0.5
RESUM_EVERY = 4096

NO_FLIP = 0
MAX_PASSED = 1
MIN_PASSED = -1


class InclinationWindow:
    """Ring buffer of (sample index, t, T, angle) with the running inclination sum."""

    def __init__(self, n: int) -> None:
        if n < 3:
            raise ValueError(f"window needs at least 3 samples (got {n})")
        self.n = n
        self.time_s = [0.0] * n
        self.torque_nm = [0.0] * n
        self.angle_deg = [0.0] * n
        self.index = [0] * n  # the sample's index within the run
        self._slopes = [0.0] * n  # slope of the pair ending at each slot
        self.head = -1  # slot of the newest sample
        self.count = 0
        self.slope_sum = 0.0  # S of eq. 46
        self.sign = 0  # M of eq. 47
        self._since_resum = 0

    def push(
        self,
        index: int,
        time_s: float,
        torque_nm: float,
        angle_deg: float,
        nominal_dt_s: float,
    ) -> int:
        """Add the newest sample; MAX_PASSED / MIN_PASSED when M changes sign, else NO_FLIP."""
        n = self.n
        head = self.head
        new = head + 1
        if new == n:
            new = 0
        slopes = self._slopes
        if self.count:
            dt_s = time_s - self.time_s[head]
            floor_s = MIN_DT_FRACTION * nominal_dt_s if nominal_dt_s > 0.0 else 1e-6
            dt_s = max(dt_s, floor_s)
            slope = (torque_nm - self.torque_nm[head]) / dt_s
        else:
            slope = 0.0
        if self.count == n:
            # The slot being overwritten holds the oldest sample; the pair that
            # leaves the window is the one ending at the next-oldest slot.
            leaving = new + 1
            if leaving == n:
                leaving = 0
            self.slope_sum += slope - slopes[leaving]
            slopes[leaving] = 0.0
        else:
            self.slope_sum += slope
            self.count += 1
        slopes[new] = slope
        self.index[new] = index
        self.time_s[new] = time_s
        self.torque_nm[new] = torque_nm
        self.angle_deg[new] = angle_deg
        self.head = new
        self._since_resum += 1
        if self._since_resum >= RESUM_EVERY:
            self._since_resum = 0
            self.slope_sum = sum(slopes)
        if self.count < n:
            return NO_FLIP
        s = self.slope_sum
        if s > 0.0:
            if self.sign < 0:
                self.sign = 1
                return MIN_PASSED
            self.sign = 1
        elif s < 0.0:
            if self.sign > 0:
                self.sign = -1
                return MAX_PASSED
            self.sign = -1
        return NO_FLIP

    def slots_oldest_first(self) -> list[int]:
        """Slot numbers of the samples in the window, oldest first."""
        n = self.n
        if self.count < n:
            return list(range(self.count))
        start = self.head + 1
        return [(start + k) % n for k in range(n)]

    def argmax(self, after_index: int = -1) -> int:
        """Slot of the largest torque among samples with index > ``after_index`` (eq. 48)."""
        best = -1
        for slot in self.slots_oldest_first():
            if self.index[slot] > after_index and (
                best < 0 or self.torque_nm[slot] >= self.torque_nm[best]
            ):
                best = slot
        return best

    def argmin(self, after_index: int = -1) -> int:
        """Slot of the smallest torque among samples with index > ``after_index`` (eq. 50)."""
        best = -1
        for slot in self.slots_oldest_first():
            if self.index[slot] > after_index and (
                best < 0 or self.torque_nm[slot] < self.torque_nm[best]
            ):
                best = slot
        return best
