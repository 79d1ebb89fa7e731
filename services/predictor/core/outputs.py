"""What the core reports: one :class:`CoreEvent` per stick-slip event, one :class:`CoreDecision`.

Both are plain values (no station, no run id, no wall clock); the service
wraps them into :mod:`shared.messages` types, ``boltwatch predict`` prints them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from shared.messages import Prediction, StopReasonName


@dataclass(frozen=True, slots=True)
class CoreEvent:
    """Stick-slip event j and its figures (paper Fig. 3); None where not yet defined."""

    index: int  # j, from 1
    time_s: float  # t_j of the torque peak (trace time)
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
    predictions: list[Prediction] = field(default_factory=list)


@dataclass(frozen=True, slots=True)
class CoreDecision:
    """Stop the tool now, decided at the sample at ``time_s``."""

    time_s: float
    reason: StopReasonName
    detail: str
    torque_nm: float
    force_n: float | None
    predicted_force_n: float | None  # the force the stop is predicted to land on (force target)
    predicted_torque_nm: float | None = None  # the torque it lands on (torque target)
