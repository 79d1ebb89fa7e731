"""Measured stick-slip events against the analytical envelopes (paper Figures 13-15).

Input: per slip event j (in order) the onset time, the model time t_j of the
onset (φ_m / φ̇_m, :mod:`shared.model.timing`), the torque peak before and the
torque trough after it, and the preload plateaus (one more than events: the
plateau before the first slip). Metrics as the paper's Figure 3:

    Δt_j  = onset_j − onset_(j−1),      f_ss,j = 1 / Δt_j
    ΔT_j  = peak_j − trough_j
    ΔF_j  = plateau_(j+1) − plateau_j  (the step made by slip j)
    K1_j  = f_ss,j · t_j,   K2_j = ΔF_j / Δt_j · φ̇_m,   K3_j = ΔT_j / t_j · φ̇_m   (31-33)

The first event has no Δt and is left out. Each metric is compared with the
full-relief bounds of eqs. 21-26 at t_j and the bands of eqs. 34-39; nothing
is widened. Pure numpy.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from shared.model.characteristic_constants import k1_of, k2_of, k3_of
from shared.model.joint_model import JointModel

Array = NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class EventMetrics:
    """Figure 3 metrics of the events 1..n−1 of one run (arrays of equal length)."""

    model_time_s: Array
    frequency_hz: Array
    force_step_n: Array
    torque_drop_nm: Array
    k1: Array
    k2: Array
    k3: Array


@dataclass(frozen=True, slots=True)
class Share:
    """How many of ``count`` values fall below, inside and above their envelope."""

    below: int
    inside: int
    above: int

    @property
    def count(self) -> int:
        return self.below + self.inside + self.above


def event_metrics(
    onset_time_s: Array,
    onset_model_time_s: Array,
    peak_torque_nm: Array,
    trough_torque_nm: Array,
    plateau_forces_n: Array,
    motor_speed_rad_s: float,
) -> EventMetrics:
    """The metrics of every event but the first (see the module docstring)."""
    # a slip still under way at the end of the run has no plateau after it yet
    n = min(len(onset_time_s), len(plateau_forces_n) - 1)
    onset_time_s, onset_model_time_s = onset_time_s[:n], onset_model_time_s[:n]
    peak_torque_nm, trough_torque_nm = peak_torque_nm[:n], trough_torque_nm[:n]
    if n < 2:
        empty = np.zeros(0)
        return EventMetrics(empty, empty, empty, empty, empty, empty, empty)
    period_s = np.diff(onset_time_s)
    t_s = onset_model_time_s[1:]
    force_step_n = np.diff(plateau_forces_n[: n + 1])[1:]
    torque_drop_nm = (peak_torque_nm - trough_torque_nm)[1:]
    frequency_hz = 1.0 / period_s
    return EventMetrics(
        model_time_s=t_s,
        frequency_hz=frequency_hz,
        force_step_n=force_step_n,
        torque_drop_nm=torque_drop_nm,
        k1=k1_of(frequency_hz, t_s),
        k2=k2_of(force_step_n, period_s, motor_speed_rad_s),
        k3=k3_of(torque_drop_nm, t_s, motor_speed_rad_s),
    )


def share(values: Array, low: Array | float, high: Array | float) -> Share:
    """Count ``values`` below ``low``, within [low, high], above ``high``."""
    below = int(np.count_nonzero(values < low))
    above = int(np.count_nonzero(values > high))
    return Share(below, len(values) - below - above, above)


def envelope_shares(metrics: EventMetrics, model: JointModel) -> dict[str, Share]:
    """Each metric against its full-relief envelope (eqs. 21-26 at t_j, 34-39)."""
    t_s = metrics.model_time_s
    bands = model.constant_bands()
    return {
        "frequency": share(
            metrics.frequency_hz,
            model.stick_slip_frequency_min_hz(t_s),
            model.stick_slip_frequency_max_hz(t_s),
        ),
        "force_step": share(
            metrics.force_step_n, model.force_step_min_n(t_s), model.force_step_max_n(t_s)
        ),
        "torque_drop": share(
            metrics.torque_drop_nm, model.torque_drop_min_nm(t_s), model.torque_drop_max_nm(t_s)
        ),
        "k1": share(metrics.k1, bands.k1_min, bands.k1_max),
        "k2": share(metrics.k2, bands.k2_min, bands.k2_max),
        "k3": share(metrics.k3, bands.k3_min, bands.k3_max),
    }
