"""How far the predictions of a run were off (paper Section 6.5, Figures 22, 23).

Event j-h published, among its ``predictions``, the one of horizon h: its
guess p'_j = (t'_j, T'_j, F'_j) of event j (eq. 60). Matching it with the
event j that came, p_j = (t_j, T_j, F_j) (eq. 59), gives the absolute errors
of Figure 22 and the relative ones of Figure 23.

One sign convention for every error: measured − predicted. Positive means the
prediction fell short (too low, or too early); negative means it overshot (too
high, or too late):

    time     t_j − t'_j          relative (t_j − t'_j) / Δt_j     Δt_j = t_j − t_(j−1)
    torque   T_j − T'_j          relative (T_j − T'_j) / T_j      eq. 62
    force    F_j − F'_j          relative (F_j − F'_j) / F_j      eq. 63

Torque and force are the paper's eqs. 62 and 63. Its eq. 61 writes time the
other way round, ε_t = (t'_j − t_j) / Δt_j; here the relative time error is
−ε_t, so that the three panels of a figure read alike (a late prediction is
below zero, like a prediction too high). Magnitudes, and so Figure 24 and the
predictor's own scores (which average |ε|), are the same either way.
Times are the predictor's run times (``time_s`` of events and predictions).
"""

from __future__ import annotations

from dataclasses import dataclass

from shared.contract import StickSlipEvent

HORIZONS = (1, 2, 3)


@dataclass(frozen=True, slots=True)
class PredictionError:
    """The error of the horizon-``horizon`` prediction of event ``index``: measured − predicted."""

    index: int  # j
    horizon: int  # h: made at event j-h
    time_s: float  # t_j, run time of the actual event
    time_error_s: float  # t_j - t'_j: negative when the prediction was late
    torque_error_nm: float  # T_j - T'_j
    force_error_n: float | None  # F_j - F'_j
    relative_time: float | None  # (t_j - t'_j) / Δt_j, i.e. -ε_t of eq. 61
    relative_torque: float | None  # eq. 62
    relative_force: float | None  # eq. 63


def prediction_errors(events: list[StickSlipEvent]) -> list[PredictionError]:
    """Every prediction of ``events`` that a later event of the run can be compared with."""
    by_index = {event.index: event for event in events}
    errors: list[PredictionError] = []
    for made_at in events:
        for prediction in made_at.predictions:
            actual = by_index.get(made_at.index + prediction.horizon)
            if actual is None:
                continue
            force_error = None
            relative_force = None
            if actual.plateau_force_n is not None and prediction.plateau_force_n is not None:
                force_error = actual.plateau_force_n - prediction.plateau_force_n
                if actual.plateau_force_n != 0.0:
                    relative_force = force_error / actual.plateau_force_n
            time_error = actual.time_s - prediction.time_s
            torque_error = actual.peak_torque_nm - prediction.peak_torque_nm
            period = actual.period_s
            errors.append(
                PredictionError(
                    actual.index,
                    prediction.horizon,
                    actual.time_s,
                    time_error,
                    torque_error,
                    force_error,
                    time_error / period if period else None,
                    torque_error / actual.peak_torque_nm if actual.peak_torque_nm else None,
                    relative_force,
                )
            )
    errors.sort(key=lambda error: (error.horizon, error.index))
    return errors
