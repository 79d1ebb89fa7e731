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
  Torque target on a joint that sticks and slips: the halt level of the stick
  phase under way comes from :mod:`.halt_planner` (a slip during the halt
  costs the whole torque drop), and the rule fires when the torque plus the
  reaction's worth of stick ramp reaches it.

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
        self._halt_nm = math.nan
        self._halt_rate_nm = math.nan
        self._halt_drop_nm = math.nan
        self._halt_samples_left = 0
        self._halt_max_nm = -math.inf
        self._previous_value = math.nan

    def plan_halt(
        self,
        halt_nm: float | None,
        rate_nm_per_sample: float = math.nan,
        drop_nm: float = math.nan,
        valid_samples: int = 0,
    ) -> None:
        """Torque target: the torque to halt at in the stick phase now under way.

        From :class:`~.halt_planner.HaltPlanner`: below the target when the
        phase is likely to slip right at it, above when the next phase is the
        safer one to stop in. ``rate_nm_per_sample`` is the stick ramp, used to
        decide one reaction ahead of the halt. The plan holds for this phase
        only: when the torque falls by half the typical drop ``drop_nm`` (a
        slip, seen or not) the halt level becomes the target itself, and after
        ``valid_samples`` the plan is dropped (the joint no longer sticks and
        slips as predicted). None, or no plan: halt on the
        target by the usual rules (three samples over it, or the steady-ramp
        projection). A plan never aims at or past the torque limit: it is
        capped one ramp step below ``max_torque_nm``.
        """
        usable = (
            halt_nm is not None and rate_nm_per_sample > 0.0 and drop_nm > 0.0 and valid_samples > 0
        )
        self._halt_nm = (
            min(halt_nm, self._max_torque - rate_nm_per_sample)
            if usable and halt_nm is not None
            else math.nan
        )
        self._halt_rate_nm = rate_nm_per_sample
        self._halt_drop_nm = drop_nm
        self._halt_samples_left = valid_samples
        self._halt_max_nm = -math.inf

    def _halt_plan_holds(self, value: float) -> bool:
        """Count down the plan and watch for a slip; False once it no longer applies."""
        if math.isnan(self._halt_nm):
            return False
        self._halt_samples_left -= 1
        self._halt_max_nm = max(self._halt_max_nm, value)
        if self._halt_samples_left < 0:
            self._halt_nm = math.nan
            return False
        if value < self._halt_max_nm - 0.5 * self._halt_drop_nm and self._target_torque:
            # slipped: the plan was for the phase that just ended; until the
            # event is confirmed and a new plan made, this phase halts on target
            self._halt_nm = self._target_torque
            self._halt_max_nm = value
        return True

    def _decide(
        self,
        time_s: float,
        reason: StopReasonName,
        detail: str,
        torque_nm: float,
        force_n: float | None,
        predicted: float | None = None,
    ) -> CoreDecision:
        self.decision = CoreDecision(
            time_s=time_s,
            reason=reason,
            detail=detail,
            torque_nm=torque_nm,
            force_n=force_n,
            # what the rule predicted the stop lands on: force when the target is a force
            predicted_force_n=predicted if self._target_force is not None else None,
            predicted_torque_nm=predicted if self._target_force is None else None,
        )
        return self.decision

    def on_sample(
        self, time_s: float, torque_nm: float, force_n: float | None, turned_deg: float
    ) -> CoreDecision | None:
        """Hard limits and the conventional target; None to go on.

        ``force_n`` None: the sample has no force (none measured yet in this run),
        so the force rules wait for one.
        """
        if self.decision is not None:
            return None
        need = self.settings.limit_samples
        self._over_torque = self._over_torque + 1 if torque_nm >= self._max_torque else 0
        if self._over_torque >= need:
            return self._decide(
                time_s, "torque_limit", f"torque ≥ {self._max_torque:g} Nm", torque_nm, force_n
            )
        over_force = force_n is not None and force_n >= self._max_force
        self._over_force = self._over_force + 1 if over_force else 0
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
            if force_n is None:
                return None
            value, target, quantity, unit = force_n, self._target_force, "force", "N"
        elif self._target_torque is not None:
            value, target, quantity, unit = torque_nm, self._target_torque, "torque", "Nm"
        else:
            return None
        self._ramp.add(value)
        self._over_target = self._over_target + 1 if value >= target else 0
        previous, self._previous_value = self._previous_value, value
        if self._target_torque is not None and self._halt_plan_holds(value):
            # one spike is not a reason: the torque now is taken as at most two
            # ramp steps above the sample before
            now = value if math.isnan(previous) else min(value, previous + 2.0 * self._halt_rate_nm)
            at_halt = now + self._halt_rate_nm * self._lead_samples
            if at_halt < self._halt_nm:
                return None
            return self._decide(
                time_s,
                "target_reached",
                f"{quantity} {value:.5g} {unit} + ramp: {at_halt:.5g} {unit} at the halt ≥ "
                f"planned {self._halt_nm:.5g} {unit} (target {target:g} {unit}, slip risk)",
                torque_nm,
                force_n,
                at_halt,
            )
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

    def on_input_fault(self, time_s: float, bad_samples: int) -> CoreDecision | None:
        if self.decision is not None:
            return None
        return self._decide(
            time_s,
            "input_fault",
            f"{bad_samples} unusable samples in a row",
            math.nan,
            None,
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
        force = force_now_n
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
