"""When to stop the tool, and why (paper Sec. 6.6 and the program's hard limits).

Checked on every sample (O(1)):

- torque_limit / force_limit / angle_limit: the program's hard limit held
  for ``limit_samples`` samples in a row (one spike is not a reason);
- target_reached: the measured force (torque on torque-only stations) at or
  above its target for :data:`TARGET_SAMPLES` samples in a row. This is the
  conventional stop, and it is what stops a joint without stick-slip; with
  stick-slip the plateau rule below usually decides first. On a steady ramp
  (a joint sliding smoothly, or the torque of a long stick phase) the value
  the motor will stop at is projected over the station's reaction
  (:mod:`.ramp_estimator`), and the rule fires when that reaches the target:
  waiting for the measurement would overshoot by the reaction's worth of ramp.

Checked once per stick-slip event j (after its slip, on the new plateau):

- plateau_closest, eq. 65 (force) / eq. 64 (torque): stop when the next
  plateau is predicted no closer to the target than the current one,
  |F_next - F_target| ≥ |F_now - F_target|. F_now is measured (the plateau
  the joint sits on after slip j); F_next = F_now + the predicted step.
  Torque-only: T_now and T_next are the predicted peaks of the current and
  the next plateau (the peak torque of a plateau is F · r · μ_stick, so it
  ranks plateaus like the force does);
- intensity_limit, eq. 70: I_process > I_max;
- constant_out_of_band, eq. 71: |mean(K_i of the n_K events before) - K_i,now|
  ≥ S_i, with S_i given as a fraction of that mean; only when configured.
  And, when the station's joint is known, the median of the last n_K K_i
  outside the model's band widened by its known uncertainty
  (:mod:`.model_bands`).

The first decision is latched: one decision per run.
"""

from __future__ import annotations

import math
from collections import deque

from services.predictor.core.model_bands import BandVerdict
from services.predictor.core.outputs import CoreDecision
from services.predictor.core.ramp_estimator import RampEstimator
from services.predictor.core.settings import PredictorSettings
from shared.messages import StopReasonName

TARGET_SAMPLES = 3
#: torque target: a stick phase whose predicted peak is within this share of the
#: target may slip while the stop is on its way (see :meth:`StopPolicy.expect_peak`)
SLIP_GUARD = 0.015


class StopPolicy:
    """Per-sample and per-event stop rules with a latch."""

    def __init__(self, settings: PredictorSettings) -> None:
        self.settings = settings
        self.decision: CoreDecision | None = None
        self._over_torque = 0
        self._over_force = 0
        self._over_angle = 0
        self._over_target = 0
        self._ramp = RampEstimator()
        self._lead_samples = settings.reaction_samples + 0.5
        self._constants: tuple[deque[float], deque[float], deque[float]] = (
            deque(maxlen=settings.constant_window),
            deque(maxlen=settings.constant_window),
            deque(maxlen=settings.constant_window),
        )
        s = settings
        self._target_force = s.target_force_n if s.has_force else None
        self._target_torque = s.target_torque_nm if self._target_force is None else None
        self._max_torque = s.max_torque_nm if s.max_torque_nm is not None else math.inf
        self._max_force = s.max_force_n if s.has_force and s.max_force_n is not None else math.inf
        self._max_angle = s.max_angle_deg if s.max_angle_deg is not None else math.inf
        self._expected_peak_nm = math.nan

    def expect_peak(self, peak_nm: float | None) -> None:
        """The predicted peak torque of the stick phase now under way (torque target only).

        The settled torque of a halted tool is the torque at the halt if the
        joint sticks, but the trough after the slip if the slip starts before
        the motor has stopped. When this phase's peak is predicted within
        SLIP_GUARD of the target, the target is crossed right before the slip:
        the stop is held back, and the next stick phase, which starts below
        and ends above the target, crosses it far from its slip. If the joint
        goes on sticking after all, the stop comes at SLIP_GUARD past the target.
        """
        self._expected_peak_nm = peak_nm if peak_nm is not None else math.nan

    def _decide(
        self,
        time_s: float,
        reason: StopReasonName,
        detail: str,
        torque_nm: float,
        force_n: float,
        predicted: float | None = None,
    ) -> CoreDecision:
        self.decision = CoreDecision(
            time_s=time_s,
            reason=reason,
            detail=detail,
            torque_nm=torque_nm,
            force_n=None if math.isnan(force_n) else force_n,
            predicted_force_n=predicted,
        )
        return self.decision

    def on_sample(
        self, time_s: float, torque_nm: float, force_n: float, turned_deg: float
    ) -> CoreDecision | None:
        """Hard limits and the conventional target; None to go on."""
        if self.decision is not None:
            return None
        need = self.settings.limit_samples
        self._over_torque = self._over_torque + 1 if torque_nm >= self._max_torque else 0
        if self._over_torque >= need:
            return self._decide(
                time_s, "torque_limit", f"torque ≥ {self._max_torque:g} Nm", torque_nm, force_n
            )
        self._over_force = self._over_force + 1 if force_n >= self._max_force else 0
        if self._over_force >= need:
            return self._decide(
                time_s, "force_limit", f"force ≥ {self._max_force:g} N", torque_nm, force_n
            )
        self._over_angle = self._over_angle + 1 if turned_deg >= self._max_angle else 0
        if self._over_angle >= need:
            return self._decide(
                time_s, "angle_limit", f"angle turned ≥ {self._max_angle:g}°", torque_nm, force_n
            )
        if self._target_force is not None:
            value, target, quantity, unit = force_n, self._target_force, "force", "N"
        elif self._target_torque is not None:
            value, target, quantity, unit = torque_nm, self._target_torque, "torque", "Nm"
        else:
            return None
        self._ramp.add(value)
        self._over_target = self._over_target + 1 if value >= target else 0
        if self._target_torque is not None and self._holds_back(value, target):
            return None
        if self._over_target >= TARGET_SAMPLES:
            return self._decide(
                time_s,
                "target_reached",
                f"{quantity} {value:.5g} {unit} ≥ target {target:g} {unit}",
                torque_nm,
                force_n,
            )
        projected = self._ramp.projected(self._lead_samples)
        if projected >= target:
            return self._decide(
                time_s,
                "target_reached",
                f"{quantity} ramp projected to {projected:.5g} {unit} at the halt "
                f"≥ target {target:g} {unit}",
                torque_nm,
                force_n,
                projected,
            )
        return None

    def _holds_back(self, value: float, target: float) -> bool:
        """Torque target: this stick phase's predicted slip is too close to the target."""
        peak = self._expected_peak_nm
        if not abs(peak - target) <= SLIP_GUARD * target:
            return False
        return value < target * (1.0 + SLIP_GUARD)

    def on_input_fault(self, time_s: float, bad_samples: int) -> CoreDecision | None:
        if self.decision is not None:
            return None
        return self._decide(
            time_s,
            "input_fault",
            f"{bad_samples} unusable samples in a row",
            math.nan,
            math.nan,
        )

    def on_event(
        self,
        time_s: float,
        torque_nm: float,
        force_now_n: float | None,
        force_next_n: float | None,
        peak_now_nm: float | None,
        peak_next_nm: float | None,
        process_intensity: float,
        constants: tuple[float | None, float | None, float | None],
        band_verdict: BandVerdict | None = None,
    ) -> CoreDecision | None:
        """Rules evaluated after each event's slip (eqs. 64, 65, 70, 71)."""
        if self.decision is not None:
            return None
        force = force_now_n if force_now_n is not None else math.nan
        limit = self.settings.max_process_intensity
        if limit is not None and process_intensity > limit:
            return self._decide(
                time_s,
                "intensity_limit",
                f"I_process {process_intensity:.4g} > I_max {limit:.4g} (eq. 70)",
                torque_nm,
                force,
            )
        if band_verdict is not None:
            return self._decide(
                time_s, "constant_out_of_band", band_verdict.detail(), torque_nm, force
            )
        band = self.settings.constant_band
        if band is not None:
            pairs = zip(self._constants, constants, strict=True)
            for number, (history, value) in enumerate(pairs, 1):
                if value is None:
                    continue
                if len(history) == self.settings.constant_window:
                    mean = sum(history) / len(history)
                    if mean != 0.0 and abs(mean - value) >= band * abs(mean):
                        return self._decide(
                            time_s,
                            "constant_out_of_band",
                            f"K{number} = {value:.4g} off its running mean {mean:.4g} (eq. 71)",
                            torque_nm,
                            force,
                        )
                history.append(value)
        target_force = self._target_force
        if target_force is not None and force_now_n is not None and force_next_n is not None:
            if abs(force_next_n - target_force) >= abs(force_now_n - target_force):
                return self._decide(
                    time_s,
                    "plateau_closest",
                    f"plateau {force_now_n:.0f} N; next {force_next_n:.0f} N is no closer to "
                    f"{target_force:g} N (eq. 65)",
                    torque_nm,
                    force,
                    force_next_n,
                )
            return None
        target_torque = self._target_torque
        if (
            target_torque is not None
            and peak_now_nm is not None
            and peak_next_nm is not None
            and abs(peak_next_nm - target_torque) >= abs(peak_now_nm - target_torque)
        ):
            return self._decide(
                time_s,
                "plateau_closest",
                f"peak {peak_now_nm:.4g} Nm; next {peak_next_nm:.4g} Nm is no closer to "
                f"{target_torque:g} Nm (eq. 64)",
                torque_nm,
                force,
                peak_next_nm,
            )
        return None
