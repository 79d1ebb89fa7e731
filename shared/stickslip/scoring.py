"""How good past predictions were (paper eqs. 57-63).

When event j arrives, each prediction p'_j = (t'_j, T'_j, F'_j) made for it
(eq. 60) is compared with the actual p_j = (t_j, T_j, F_j) (eq. 59):

- ε_t = (t'_j - t_j) / Δt_j      eq. 61
- ε_T = (T_j - T'_j) / T_j       eq. 62
- ε_F = (F_j - F'_j) / F_j       eq. 63

and the system-immanent uncertainty of the process itself, the relative
peak-to-peak torque difference δT_j/T_j and the relative force step
ΔF_j/F_j (eqs. 57, 58; printed there as T/ΔT, but the paper's values of
about 5 % only fit the relative difference). Mean absolute values per
horizon are kept; a prediction is useful when its error is below the
immanent uncertainty.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from shared.contract import Prediction


@dataclass(slots=True)
class ErrorSums:
    """Sums of |ε| for one horizon (or of the immanent uncertainty)."""

    count_t: int = 0
    sum_t: float = 0.0
    count_torque: int = 0
    sum_torque: float = 0.0
    count_force: int = 0
    sum_force: float = 0.0

    def means(self) -> dict[str, float | None]:
        return {
            "time": self.sum_t / self.count_t if self.count_t else None,
            "torque": self.sum_torque / self.count_torque if self.count_torque else None,
            "force": self.sum_force / self.count_force if self.count_force else None,
        }


@dataclass(slots=True)
class PredictionScores:
    """Errors of past predictions by horizon, and the immanent uncertainty."""

    by_horizon: dict[int, ErrorSums] = field(default_factory=dict)
    immanent: ErrorSums = field(default_factory=ErrorSums)
    _pending: dict[int, list[Prediction]] = field(default_factory=dict)

    def remember(self, made_at_index: int, predictions: list[Prediction]) -> None:
        """Keep the predictions made at event ``made_at_index`` for the events they target."""
        for prediction in predictions:
            self._pending.setdefault(made_at_index + prediction.horizon, []).append(prediction)

    def score(
        self,
        index: int,
        time_s: float,
        period_s: float | None,
        peak_torque_nm: float,
        plateau_force_n: float | None,
        previous_peak_nm: float | None,
        force_step_n: float | None,
    ) -> None:
        """Score every prediction made for event ``index`` against what happened."""
        if previous_peak_nm is not None and peak_torque_nm != 0.0:
            self.immanent.count_torque += 1
            self.immanent.sum_torque += abs(peak_torque_nm - previous_peak_nm) / abs(peak_torque_nm)
        if force_step_n is not None and plateau_force_n:
            self.immanent.count_force += 1
            self.immanent.sum_force += abs(force_step_n / plateau_force_n)
        for prediction in self._pending.pop(index, []):
            sums = self.by_horizon.setdefault(prediction.horizon, ErrorSums())
            if period_s:
                sums.count_t += 1
                sums.sum_t += abs((prediction.time_s - time_s) / period_s)  # eq. 61
            if peak_torque_nm != 0.0:
                sums.count_torque += 1
                sums.sum_torque += abs(
                    (peak_torque_nm - prediction.peak_torque_nm) / peak_torque_nm
                )  # eq. 62
            if plateau_force_n and prediction.plateau_force_n is not None:
                sums.count_force += 1
                sums.sum_force += abs(
                    (plateau_force_n - prediction.plateau_force_n) / plateau_force_n
                )  # eq. 63

    def summary(self) -> dict[str, dict[str, float | None]]:
        """Mean |ε| per horizon (keys "1", "2", "3") and "immanent"."""
        out = {str(h): sums.means() for h, sums in sorted(self.by_horizon.items())}
        out["immanent"] = self.immanent.means()
        return out
