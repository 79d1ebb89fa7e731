"""Did the motor drive through a torque drop? What tells a slip from the tool letting go.

A stick-slip event is a drop of the torque *under a driving motor*: the
angle sensor reports the motor angle φ_m, which turns on at its speed
through the stick phase, the slip and the next stick phase (paper Fig. 1,
eqs. 9, 10: the screw stops and slides, the motor does not). The torque also
drops, with no stick-slip at all, when

- the tool lets go after its last step (its controller stops the motor and
  the drive train unwinds: on a CS351 the "torsion release");
- the controller pauses between tightening steps;
- a step ends and the next one runs at a lower speed (the motor slows down
  and the torque with it).

In each of these the motor stands or slows down while the torque falls. So
a drop counts as a slip only if the angle advanced from the peak to the
sample that confirmed the slip (a renewed rise: the window's inclination
turned positive again, eq. 47) by at least :data:`DRIVE_FRACTION` of what the
motor's speed before the peak would have turned in that time::

    |φ(now) - φ(peak)|  ≥  DRIVE_FRACTION · |ω_before| · (t_now - t_peak) - tolerance
    ω_before = (φ(peak) - φ(peak - LOOKBACK)) / (t(peak) - t(peak - LOOKBACK))

and only if the motor was turning before the peak at all (a drop while it
stands is a pause). The tolerance is :data:`TOLERANCE_D2` medians of the
angle's |second difference| over the look-back (the angle's noise: for a
motor at constant speed d2 is noise only, see :mod:`.second_difference`):
three σ of the difference of two noisy angles (1.65 σ per median; the
difference of two has √2 σ), or about three steps of a quantized encoder.
It is computed when a drop is judged, not per sample (drops above the noise
floor are about 1 % of the samples). With two σ, one true slip
in 7901 of the detection benchmark was refused (a slow motor, 0.14 rad/s,
confirmed two samples after its peak: an angle advance of 0.016° expected
against noise of 0.011°); with three, none. The direction of turning is the
sign of ω_before, so an angle counted negative works alike.

A station whose angle never moves (no encoder: the signal stays constant)
gives no evidence either way: every drop above the noise floor is a slip, as
before this check existed.

Measured (``tests/benchmarks/bench_event_detection.py``, the rig's true
slips): recall unchanged by this check; on real CS351 runs the tool's
release and the steps' pauses and slow-downs no longer count (see the README).
O(1) per sample (a ring of times and angles), O(LOOKBACK) per candidate slip.
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
        """True if the motor drove from the peak to now as it drove before the peak.

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
