"""Did the motor drive through a torque drop? What tells a slip from the tool letting go.

A stick-slip event is a drop of the torque *under a driving motor* (paper
Fig. 1, eqs. 9, 10: the screw stops and slides, the motor does not); the tool
letting go after its last step, a pause between steps and a step to a lower
speed drop the torque with the motor standing or slowing down. So a drop
counts as a slip only if the angle advanced from the peak to the sample that
confirmed the slip by at least :data:`DRIVE_FRACTION` of what the motor's
speed before the peak would have turned, less :data:`TOLERANCE_D2` medians of
the angle's noise, and only if the motor was turning before the peak; an
angle that never moves gives no evidence either way. O(1) per sample, the
check only per candidate slip. The rule, its tolerance and what it changed
on real runs: ``docs/explanation/algorithm.md``, "A slip needs a driving motor".
"""

from __future__ import annotations

import statistics

CAPACITY = 4096  # samples kept (4 s at 1 kHz), far more than the look-back needs
LOOKBACK_SAMPLES = 32  # the motor's speed before a peak, over this many samples at most
MIN_LOOKBACK_SAMPLES = 16  # fewer before the peak (the run's start): not judged
DRIVE_FRACTION = 0.5
TOLERANCE_D2 = 2.6


class MotorMotion:
    """The recent (time, angle) of the run by sample index, and the angle's noise."""

    def __init__(self) -> None:
        self._time_s = [0.0] * CAPACITY
        self._angle_deg = [0.0] * CAPACITY
        self.count = 0  # samples added; the newest has index count - 1
        self._first_angle_deg = 0.0
        self._turned = False  # the angle has moved since the run's first sample
        self._last_held = -1  # the newest sample whose angle was held, not measured

    def add(self, time_s: float, angle_deg: float, measured: bool = True) -> None:
        """The next accepted sample's time and (finite) motor angle; measured False: held."""
        slot = self.count % CAPACITY
        self._time_s[slot] = time_s
        self._angle_deg[slot] = angle_deg
        if not measured:
            self._last_held = self.count
        if self._turned:
            pass
        elif self.count == 0:
            self._first_angle_deg = angle_deg
        elif angle_deg != self._first_angle_deg:
            self._turned = True
        self.count += 1

    def drove_through(self, peak_index: int, now_index: int) -> bool:
        """True if the motor drove from the peak to now as it drove before the peak::

            |φ(now) - φ(peak)|  >=  DRIVE_FRACTION · |ω_before| · (t_now - t_peak) - tolerance
            ω_before = (φ(peak) - φ(peak - LOOKBACK)) / (t(peak) - t(peak - LOOKBACK))

        with the tolerance TOLERANCE_D2 medians of the angle's |second difference|
        over the look-back (three σ of the difference of two noisy angles).

        True too when it cannot be judged: an angle that never moved, a held
        (not measured) angle since the look-back began, too few samples before
        the peak, or samples no longer kept.
        """
        oldest = max(0, self.count - CAPACITY)
        first = max(oldest, peak_index - LOOKBACK_SAMPLES)
        if (
            not self._turned
            or self._last_held >= first  # a held angle looks like a standing motor
            or peak_index - first < MIN_LOOKBACK_SAMPLES
            or not peak_index < now_index < self.count
        ):
            return True
        t0, a0 = self._at(first)
        t_peak, a_peak = self._at(peak_index)
        t_now, a_now = self._at(now_index)
        if t_peak <= t0 or t_now <= t_peak:
            return True
        tolerance = TOLERANCE_D2 * self._noise_d2_deg(first, peak_index)
        turned_before = a_peak - a0
        if abs(turned_before) <= tolerance:
            return False  # the motor stood before the peak: a pause, not a slip
        direction = 1.0 if turned_before > 0.0 else -1.0
        expected = abs(turned_before) * (t_now - t_peak) / (t_peak - t0)
        return direction * (a_now - a_peak) >= DRIVE_FRACTION * expected - tolerance

    def _noise_d2_deg(self, first: int, last: int) -> float:
        """Median |second difference| of the angle over samples first..last."""
        angles = [self._angle_deg[index % CAPACITY] for index in range(first, last + 1)]
        return statistics.median(
            abs(a - 2.0 * b + c) for a, b, c in zip(angles[2:], angles[1:], angles, strict=False)
        )

    def _at(self, index: int) -> tuple[float, float]:
        slot = index % CAPACITY
        return self._time_s[slot], self._angle_deg[slot]
