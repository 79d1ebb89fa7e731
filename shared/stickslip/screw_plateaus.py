"""Torque-only stations: the plateaus from the screw angle, in torque units. O(1) per event.

Without a force sensor the plateau the joint sits on is seen only through
the next peak torque, T_peak,j+1 = μ_stick,j+1 · r · F_j (eq. 9), and
μ_stick scatters from stick phase to stick phase: a line through the last
peaks (Sec. 6.4) inherits that scatter. The screw angle does not: during a
stick phase the screw stands and the extension twists, T = k_e (φ_m - φ_b)
(eq. 9), so

    k_e  = (T_peak,j - T_min,j-1) / (φ_m,peak,j - φ_m,min,j-1)      the stick ramp
    β_j  = φ_m,min,j - T_min,j / k_e                                 the screw after slip j

(β is φ_b up to a constant: the run's first angle is zero). The preload is
F_j = k_s φ_b,j (eq. 8), so the peaks are *linear* in β, exactly:

    T_peak,j+1 = μ_stick,j+1 r k_s (β_j + β_0)  ≈  A + B β_j

A least-squares line over the pairs (β_j, T_peak,j+1) of the run (running
sums with forgetting factor FORGET, O(1) per event: about 1/(1 - FORGET)
recent events count) averages the friction scatter over many events and
also absorbs a constant error of k_e (T/k_e is itself linear in β). The
plateau in torque units, u_j = A + B β_j, is proportional to F_j, so the
next one follows from the step ratio ΔF ∝ F of the lumped model (eqs.
18-24: every Δφ_b is proportional to φ_m, hence to F):

    u_j+1 = u_j (1 + mean of the last STEP_POINTS relative steps)
"""

from __future__ import annotations

import itertools
import math
import statistics
from collections import deque

KE_POINTS = 9  # stick ramps in the running median of k_e
STEP_POINTS = 3
MIN_PAIRS = 6  # pairs before the line is trusted
FORGET = 0.95  # weight of a pair per later event: the line follows a slowly drifting μ, k_e


class ScrewPlateaus:
    """Fed once per event with its peak and trough; :meth:`plateaus` gives (u_j, u_j+1)."""

    def __init__(self) -> None:
        self._k_e: deque[float] = deque(maxlen=KE_POINTS)
        self._last_trough: tuple[float, float] | None = None  # (angle rad, torque Nm)
        self._beta: float | None = None  # β of the plateau the joint is on
        self._us: deque[float] = deque(maxlen=STEP_POINTS + 1)
        self._betas: deque[float] = deque(maxlen=STEP_POINTS + 1)
        self._count = 0
        self._n = 0.0
        self._sx = self._sy = self._sxx = self._sxy = 0.0

    def on_event(
        self, peak_angle_deg: float, peak_nm: float, trough_angle_deg: float, trough_nm: float
    ) -> tuple[float, float] | None:
        """Add event j; the current and next plateau in torque units, or None."""
        peak_rad = math.radians(peak_angle_deg)
        trough_rad = math.radians(trough_angle_deg)
        if self._last_trough is not None:
            ramp_rad = peak_rad - self._last_trough[0]
            ramp_nm = peak_nm - self._last_trough[1]
            if ramp_rad > 0.0 and ramp_nm > 0.0:
                self._k_e.append(ramp_nm / ramp_rad)
        self._last_trough = (trough_rad, trough_nm)
        if self._beta is not None:  # the peak that ended the plateau β
            x = self._beta
            f = FORGET
            self._count += 1
            self._n = f * self._n + 1.0
            self._sx = f * self._sx + x
            self._sy = f * self._sy + peak_nm
            self._sxx = f * self._sxx + x * x
            self._sxy = f * self._sxy + x * peak_nm
        if len(self._k_e) < 3:
            self._beta = None
            return None
        k_e = statistics.median(self._k_e)
        beta = trough_rad - trough_nm / k_e
        self._beta = beta
        self._betas.append(beta)
        if self._count < MIN_PAIRS:
            return None
        n = self._n
        var = self._sxx - self._sx * self._sx / n
        if var <= 0.0:
            return None
        slope = (self._sxy - self._sx * self._sy / n) / var
        intercept = (self._sy - slope * self._sx) / n
        if slope <= 0.0:
            return None
        us = [intercept + slope * b for b in self._betas]
        now = us[-1]
        steps = [(b - a) / a for a, b in itertools.pairwise(us) if a > 0.0]
        if now <= 0.0 or not steps:
            return None
        ratio = sum(steps) / len(steps)
        if ratio <= 0.0:
            return None
        return now, now * (1.0 + ratio)
