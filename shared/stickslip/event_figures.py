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

:class:`EventFigures` is the one type for event j: the core reports it,
``boltwatch predict`` prints it and :mod:`shared.stickslip.run_messages`
turns it into the wire message :class:`~shared.contract.messages.StickSlipEvent`
(every field but ``current_force_n`` and ``detected_at_s``, which serve the
stop rules and the tests, plus the station, the run and ``time_ns``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from shared.contract import Prediction


@dataclass(frozen=True, slots=True)
class EventFigures:
    """Stick-slip event j and its figures (paper Fig. 3); None where not yet defined."""

    index: int  # j, from 1
    time_s: float  # t_j of the torque peak (run time)
    peak_torque_nm: float  # T_max,j (eq. 48)
    min_torque_nm: float  # T_min,j after the slip (eq. 50)
    torque_drop_nm: float  # ΔT_j = T_max,j - T_min,j
    plateau_force_n: float | None  # F_j: the plateau the peak sits on (before slip j)
    force_step_n: float | None  # ΔF_j = F_j - F_{j-1}
    period_s: float | None  # Δt_j = t_j - t_{j-1}
    f_ss_hz: float | None  # 1 / Δt_j
    k1: float | None  # eq. 31
    k2: float | None  # eq. 32
    k3: float | None  # eq. 33
    intensity: float | None  # I_j, eq. 67
    process_intensity: float  # I_process, eq. 68
    current_force_n: float | None  # plateau after slip j, measured when the event was confirmed
    detected_at_s: float  # time of the sample at which the event was confirmed
    predictions: list[Prediction]  # the next events as predicted at event j (eqs. 52-56)


def torque_mean_nm(peak_torque_nm: float, min_torque_nm: float) -> float:
    """T_mean,j of eq. 66."""
    return 0.5 * (peak_torque_nm + min_torque_nm)


def event_intensity(torque_drop_nm: float, mean_torque_nm: float, f_ss_hz: float) -> float:
    """I_j = ΔT_j · |T_mean,j| · f_ss,j (eq. 67), Nm²/s; never negative."""
    return torque_drop_nm * abs(mean_torque_nm) * f_ss_hz


def event_period_s(time_s: float, previous_time_s: float | None) -> float | None:
    """Δt_j = t_j - t_(j-1); None for the first event or a peak not after the previous one."""
    if previous_time_s is not None and time_s > previous_time_s:
        return time_s - previous_time_s
    return None


def compute_figures(
    *,
    index: int,
    time_since_start_s: float,
    peak_torque_nm: float,
    min_torque_nm: float,
    plateau_force_n: float | None,
    previous_time_s: float | None,
    previous_plateau_n: float | None,
    time_s: float,
    motor_speed_rad_s: float | None,
    process_intensity_before: float = 0.0,
    current_force_n: float | None = None,
    detected_at_s: float | None = None,
    predictions: list[Prediction] | None = None,
) -> EventFigures:
    """All figures of event j; None where the previous event or the force is missing.

    ``process_intensity_before``: I_process up to event j-1; ``detected_at_s``
    defaults to the peak's time.
    """
    drop = peak_torque_nm - min_torque_nm
    period = event_period_s(time_s, previous_time_s)
    f_ss = 1.0 / period if period is not None else None
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
    process_intensity = process_intensity_before
    if intensity is not None:
        process_intensity += intensity  # eq. 68, from j = 2
    return EventFigures(
        index=index,
        time_s=time_s,
        peak_torque_nm=peak_torque_nm,
        min_torque_nm=min_torque_nm,
        torque_drop_nm=drop,
        plateau_force_n=plateau_force_n,
        force_step_n=step,
        period_s=period,
        f_ss_hz=f_ss,
        k1=k1,
        k2=k2,
        k3=k3,
        intensity=intensity,
        process_intensity=process_intensity,
        current_force_n=current_force_n,
        detected_at_s=time_s if detected_at_s is None else detected_at_s,
        predictions=[] if predictions is None else predictions,
    )
