"""Torque target: where to halt in the stick phase now under way (torque-only stations).

A halted tool keeps its torque if the joint still sticks, but a slip that
starts before the motor has stopped drops the torque by ΔT (5-12 % of the
target on the joints it was chosen on; ``tests/benchmarks/bench_torque_only.py``
measures it on drops of 2-25 %, scatter of 0-5 % and families it was not
tuned on), while a slip before the decision costs nothing. So in each stick
phase the halt torque H is the one of least expected error
(:func:`expected_error`) given the predicted slip level P̂ of this phase and
its scatter σ, measured by the core; far from the target, H is the target
itself, and no plan is made before :data:`MIN_EVENTS` events or with an input
that is not finite. The reasoning and how it was chosen against other rules:
``docs/explanation/algorithm.md``, "Stopping on a torque target: the halt plan",
and what it leaves on joints it was not tuned on: "On joints it was not tuned on".
"""

from __future__ import annotations

import math
import statistics
from collections import deque

MIN_EVENTS = 5
RESIDUALS = 8
RECENT = 5
MIN_SIGMA_FRACTION = 0.008
SEARCH_BAND = 0.06  # H searched within target · (1 ± SEARCH_BAND)
GRID_STEPS = 49
REACH_SIGMAS = 4.0  # plan only when |P̂ - T*| < REACH_SIGMAS · σ + ΔT
WAIT_PENALTY = 0.25  # share of the peak step added to e_next per phase waited


def _phi(z: float) -> float:
    return 0.5 * (1.0 + math.erf(z * 0.7071067811865476))


def expected_error(
    halt_nm: float,
    peak_nm: float,
    sigma_nm: float,
    rate_nm: float,
    drop_nm: float,
    target_nm: float,
    next_error_nm: float,
) -> float:
    """E(H), the expected |settled torque - target| of halting at H, in Nm.

    With the slip level P ~ N(P̂, σ²) and the decision one ramp step r before the halt::

        E(H) = Φ((H - r - P̂)/σ) · e_next                          slipped before: next phase
             + [Φ((H - P̂)/σ) - Φ((H - r - P̂)/σ)] · |H - ΔT - T*|  slip during the halt
             + [1 - Φ((H - P̂)/σ)] · |H - T*|                       sticks: halted at H
    """
    before = _phi((halt_nm - rate_nm - peak_nm) / sigma_nm)
    by_halt = _phi((halt_nm - peak_nm) / sigma_nm)
    return (
        before * next_error_nm
        + (by_halt - before) * abs(halt_nm - drop_nm - target_nm)
        + (1.0 - by_halt) * abs(halt_nm - target_nm)
    )


def best_halt(
    peak_nm: float,
    sigma_nm: float,
    rate_nm: float,
    drop_nm: float,
    target_nm: float,
    next_error_nm: float,
) -> tuple[float, float]:
    """(H, E(H)) of least expected error on the search grid; the target itself on a tie."""
    low = target_nm * (1.0 - SEARCH_BAND)
    step = 2.0 * SEARCH_BAND * target_nm / (GRID_STEPS - 1)
    best_h = target_nm
    best_e = expected_error(
        target_nm, peak_nm, sigma_nm, rate_nm, drop_nm, target_nm, next_error_nm
    )
    for k in range(GRID_STEPS):
        halt = low + k * step
        cost = expected_error(halt, peak_nm, sigma_nm, rate_nm, drop_nm, target_nm, next_error_nm)
        if cost < best_e:
            best_h, best_e = halt, cost
    return best_h, best_e


class HaltPlanner:
    """Per-event bookkeeping of peaks, drops and rise rates; the halt level of the next phase."""

    def __init__(self, target_nm: float) -> None:
        self.target_nm = target_nm
        self._residuals: deque[float] = deque(maxlen=RESIDUALS)
        self._rates: deque[float] = deque(maxlen=RECENT)
        self._drops: deque[float] = deque(maxlen=RECENT)
        self._predicted_nm = math.nan
        self._trough: tuple[int, float] | None = None
        self.events = 0
        self.planned = 0

    @property
    def rate_nm_per_sample(self) -> float:
        """Median rise per sample of the recent stick phases; NaN before one is known."""
        return statistics.median(self._rates) if self._rates else math.nan

    @property
    def drop_nm(self) -> float:
        """Median torque drop of the recent slips; NaN before one is known."""
        return statistics.median(self._drops) if self._drops else math.nan

    def on_event(
        self,
        peak_index: int,
        peak_nm: float,
        trough_index: int,
        trough_nm: float,
        predicted_peaks_nm: list[float],
    ) -> float | None:
        """Record event j; the halt level H for phase j+1, or None to halt on the target."""
        self.events += 1
        if math.isfinite(self._predicted_nm):
            self._residuals.append(peak_nm - self._predicted_nm)
        if self._trough is not None and peak_index > self._trough[0]:
            rate = (peak_nm - self._trough[1]) / (peak_index - self._trough[0])
            if rate > 0.0:
                self._rates.append(rate)
        self._drops.append(peak_nm - trough_nm)
        self._trough = (trough_index, trough_nm)
        self._predicted_nm = predicted_peaks_nm[0] if predicted_peaks_nm else math.nan
        return self._plan(predicted_peaks_nm)

    def _plan(self, predicted_peaks_nm: list[float]) -> float | None:
        if self.events < MIN_EVENTS or len(self._residuals) < 3 or not predicted_peaks_nm:
            return None
        target = self.target_nm
        rate = self.rate_nm_per_sample
        drop = self.drop_nm
        spread = math.sqrt(sum(e * e for e in self._residuals) / len(self._residuals))
        spread = max(spread, MIN_SIGMA_FRACTION * target)
        sigma = math.sqrt(spread * spread + rate * rate / 12.0)
        values = (rate, drop, sigma, *predicted_peaks_nm)
        if not all(math.isfinite(v) for v in values) or rate <= 0.0 or drop <= 0.0:
            return None
        peaks = [p + 0.5 * rate for p in predicted_peaks_nm]
        if abs(peaks[0] - target) >= REACH_SIGMAS * sigma + drop:
            return None
        error = 0.25 * rate  # a clean crossing, after the last horizon
        halt = target
        for k in range(len(peaks) - 1, -1, -1):
            if k + 1 < len(peaks):
                error += WAIT_PENALTY * max(0.0, peaks[k + 1] - peaks[k])
            halt, error = best_halt(peaks[k], sigma, rate, drop, target, error)
        self.planned += 1
        return halt
