"""Least-squares fits and the predictions of the next 1-3 events (paper eqs. 52-56, Sec. 6.4).

- Time: Δt grows linearly with the process (f_ss ∝ 1/t, Sec. 6.3), so the
  periods y = [t_(i+1) - t_i] (eq. 54) are fitted against x = [0 : i-1]
  (eq. 53) by least squares (eq. 52); Δt_(n+1) = p(next x) (eq. 55) and
  t_(n+1) = t_n + Δt_(n+1) (eq. 56), repeated for horizons 2 and 3.
- Peak torque: a line through the five youngest peaks (Sec. 6.4).
- Force plateau: a 2nd-order polynomial through the youngest plateaus
  (Sec. 6.4), or a line, or the last plateau plus the mean of recent steps
  (:data:`PlateauMethod`; compared in tests/benchmarks/bench_predictor_accuracy.py).

Guards: a parabola through noisy plateaus can bend down or shoot up. A
predicted plateau below the last one, or a predicted step outside
[STEP_LOW, STEP_HIGH] × the mean of the recent steps, is replaced by the
mean-step prediction. A predicted period outside [0.5, 2] × the last period
is replaced by the last period. All fits are closed-form on a few points
(pure Python, microseconds), once per event.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

from shared.contract import Prediction
from shared.stickslip.settings import PlateauMethod

HORIZONS = 3
PERIOD_POINTS = 8
PEAK_POINTS = 5  # "the youngest five", Sec. 6.4
PLATEAU_POINTS = 6
STEP_POINTS = 3
STEP_LOW = 0.25
STEP_HIGH = 2.5


def fit_line(ys: Sequence[float]) -> tuple[float, float]:
    """(a, b) of y ≈ a + b·x over x = 0..m-1, least squares (eq. 52); flat for one point."""
    m = len(ys)
    if m == 1:
        return ys[0], 0.0
    x_mean = (m - 1) / 2.0
    y_mean = sum(ys) / m
    sxx = 0.0
    sxy = 0.0
    for x, y in enumerate(ys):
        dx = x - x_mean
        sxx += dx * dx
        sxy += dx * (y - y_mean)
    slope = sxy / sxx
    return y_mean - slope * x_mean, slope


def fit_parabola(ys: Sequence[float]) -> tuple[float, float, float]:
    """(a, b, c) of y ≈ a + b·x + c·x² over x = 0..m-1 (m ≥ 3), least squares."""
    m = len(ys)
    s = [float(sum(x**k for x in range(m))) for k in range(5)]
    t = [float(sum(y * x**k for x, y in enumerate(ys))) for k in range(3)]
    # Normal equations [[s0 s1 s2] [s1 s2 s3] [s2 s3 s4]] (a b c)ᵀ = t, by Cramer's rule.
    det = _det3(s[0], s[1], s[2], s[1], s[2], s[3], s[2], s[3], s[4])
    a = _det3(t[0], s[1], s[2], t[1], s[2], s[3], t[2], s[3], s[4]) / det
    b = _det3(s[0], t[0], s[2], s[1], t[1], s[3], s[2], t[2], s[4]) / det
    c = _det3(s[0], s[1], t[0], s[1], s[2], t[1], s[2], s[3], t[2]) / det
    return a, b, c


def _det3(
    a: float, b: float, c: float, d: float, e: float, f: float, g: float, h: float, i: float
) -> float:
    return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)


def predict_periods(periods: Sequence[float]) -> list[float]:
    """Δt of the next HORIZONS events (eqs. 53-55), guarded against implausible values."""
    recent = list(periods[-PERIOD_POINTS:])
    last = recent[-1]
    a, b = fit_line(recent)
    out = []
    for h in range(HORIZONS):
        value = a + b * (len(recent) + h)
        out.append(value if 0.5 * last <= value <= 2.0 * last else last)
    return out


def predict_peaks(peaks: Sequence[float]) -> list[float]:
    """Peak torque of the next HORIZONS events: a line through the youngest five."""
    recent = list(peaks[-PEAK_POINTS:])
    a, b = fit_line(recent)
    return [a + b * (len(recent) + h) for h in range(HORIZONS)]


def predict_plateaus(plateaus: Sequence[float], method: PlateauMethod) -> list[float] | None:
    """Plateaus F_(j+1..j+3) after the known F_1..F_j; None with fewer than two known."""
    if len(plateaus) < 2:
        return None
    last = plateaus[-1]
    tail = plateaus[-STEP_POINTS - 1 :]
    steps = [b - a for a, b in itertools.pairwise(tail)]
    mean_step = sum(steps) / len(steps)
    by_mean = [last + mean_step * (h + 1) for h in range(HORIZONS)]
    recent = list(plateaus[-PLATEAU_POINTS:])
    m = len(recent)
    if method == "mean_step" or mean_step <= 0.0:
        return by_mean
    if method == "poly2" and m >= 4:
        a, b, c = fit_parabola(recent)
        fitted = [a + b * x + c * x * x for x in range(m, m + HORIZONS)]
    else:
        a, b = fit_line(recent)
        fitted = [a + b * x for x in range(m, m + HORIZONS)]
    previous = last
    for value in fitted:
        step = value - previous
        if not STEP_LOW * mean_step <= step <= STEP_HIGH * mean_step:
            return by_mean
        previous = value
    return fitted


def predict_events(
    last_time_s: float,
    periods: Sequence[float],
    peaks: Sequence[float],
    plateaus: Sequence[float],
    method: PlateauMethod,
) -> list[Prediction]:
    """Predictions for horizons 1..3 after the latest event; empty before two peaks."""
    if not periods:
        return []
    dts = predict_periods(periods)
    torques = predict_peaks(peaks)
    forces = predict_plateaus(plateaus, method)
    out = []
    time_s = last_time_s
    for h in range(HORIZONS):
        time_s += dts[h]
        out.append(
            Prediction(
                horizon=h + 1,
                time_s=time_s,
                peak_torque_nm=torques[h],
                plateau_force_n=forces[h] if forces is not None else None,
            )
        )
    return out
