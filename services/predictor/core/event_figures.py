"""Figures of one stick-slip event (paper Fig. 3, Sec. 3.3 and 6.6).

For event j with torque peak (t_j, T_max,j), the following minimum T_min,j
and the force plateau F_j the peak sits on:

- ΔT_j = T_max,j - T_min,j                      torque drop (Fig. 3)
- ΔF_j = F_j - F_(j-1)                          force step (Fig. 3)
- Δt_j = t_j - t_(j-1),  f_ss,j = 1/Δt_j        period and frequency
- K1 = f_ss · t                                 eq. 31
- K2 = ΔF/Δt · φ̇_m                              eq. 32
- K3 = ΔT/t · φ̇_m                               eq. 33
- T_mean,j = (T_max,j + T_min,j)/2              eq. 66
- I_j = ΔT_j · |T_mean,j| · f_ss,j              eq. 67
- I_process = Σ_(j≥2) I_j                       eq. 68

The paper's T_mean is positive (a tightening); a transducer that counts
the other direction negative, or a drop around zero torque, would make I_j
negative and subtract wear. The magnitude wears the tool alike, so
|T_mean| is used and no event's intensity is below zero.

t is the time since the run's first sample; φ̇_m is the program's motor
speed when known, else measured from the angle between the two peaks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Figures:
    torque_drop_nm: float
    force_step_n: float | None
    period_s: float | None
    f_ss_hz: float | None
    k1: float | None
    k2: float | None
    k3: float | None
    intensity: float | None


def torque_mean_nm(peak_torque_nm: float, min_torque_nm: float) -> float:
    """T_mean,j of eq. 66."""
    return 0.5 * (peak_torque_nm + min_torque_nm)


def event_intensity(torque_drop_nm: float, mean_torque_nm: float, f_ss_hz: float) -> float:
    """I_j = ΔT_j · |T_mean,j| · f_ss,j (eq. 67), Nm²/s; never negative."""
    return torque_drop_nm * abs(mean_torque_nm) * f_ss_hz


def compute_figures(
    *,
    time_since_start_s: float,
    peak_torque_nm: float,
    min_torque_nm: float,
    plateau_force_n: float | None,
    previous_time_s: float | None,
    previous_plateau_n: float | None,
    time_s: float,
    motor_speed_rad_s: float | None,
) -> Figures:
    """All figures of one event; None where the previous event or the force is missing."""
    drop = peak_torque_nm - min_torque_nm
    period = None
    f_ss = None
    if previous_time_s is not None and time_s > previous_time_s:
        period = time_s - previous_time_s
        f_ss = 1.0 / period
    step = None
    if plateau_force_n is not None and previous_plateau_n is not None:
        step = plateau_force_n - previous_plateau_n
    k1 = f_ss * time_since_start_s if f_ss is not None else None
    speed = motor_speed_rad_s
    if speed is not None and not math.isfinite(speed):
        speed = None
    k2 = step / period * speed if step is not None and period and speed is not None else None
    k3 = (
        drop / time_since_start_s * speed
        if speed is not None and time_since_start_s > 0.0
        else None
    )
    intensity = (
        event_intensity(drop, torque_mean_nm(peak_torque_nm, min_torque_nm), f_ss)
        if f_ss is not None
        else None
    )
    return Figures(drop, step, period, f_ss, k1, k2, k3, intensity)
