"""The target, checked on every sample: the conventional stop, and the torque halt plan.

target_reached: the measured force (torque on torque-only stations) at or
above its target for :data:`TARGET_SAMPLES` samples in a row. This is the
conventional stop, and it is what stops a joint without stick-slip; with
stick-slip the plateau rule (:mod:`.plateau_rule`) usually decides first.
On a steady ramp (a joint sliding smoothly, or the torque of a long stick
phase) the value the motor will stop at is projected over the station's
reaction (:mod:`..ramp_estimator`), and the rule fires when that reaches the
target: waiting for the measurement would overshoot by the reaction's worth
of ramp.

Torque target on a joint that sticks and slips: the halt level of the stick
phase under way comes from :mod:`..halt_planner` (a slip during the halt
costs the whole torque drop) as a :class:`HaltPlan`, and the rule fires when
the torque plus the reaction's worth of stick ramp reaches it.
"""

from __future__ import annotations

import math

from shared.stickslip.ramp_estimator import RampEstimator
from shared.stickslip.settings import PredictorSettings
from shared.stickslip.stop_rules.stop import Stop

TARGET_SAMPLES = 3


class HaltPlan:
    """Torque target: the torque to halt at in the stick phase now under way (NaN: no plan)."""

    __slots__ = ("drop_nm", "halt_nm", "max_nm", "rate_nm", "samples_left")

    def __init__(self) -> None:
        self.halt_nm = math.nan
        self.rate_nm = math.nan
        self.drop_nm = math.nan
        self.samples_left = 0
        self.max_nm = -math.inf

    def plan(
        self,
        halt_nm: float | None,
        rate_nm_per_sample: float,
        drop_nm: float,
        valid_samples: int,
        max_torque_nm: float,
    ) -> None:
        """A new plan (see :meth:`~..stop_policy.StopPolicy.plan_halt`), capped below the limit."""
        usable = (
            halt_nm is not None and rate_nm_per_sample > 0.0 and drop_nm > 0.0 and valid_samples > 0
        )
        self.halt_nm = (
            min(halt_nm, max_torque_nm - rate_nm_per_sample)
            if usable and halt_nm is not None
            else math.nan
        )
        self.rate_nm = rate_nm_per_sample
        self.drop_nm = drop_nm
        self.samples_left = valid_samples
        self.max_nm = -math.inf

    def holds(self, value: float, target_torque_nm: float | None) -> bool:
        """Count down the plan and watch for a slip; False once it no longer applies."""
        if math.isnan(self.halt_nm):
            return False
        self.samples_left -= 1
        self.max_nm = max(self.max_nm, value)
        if self.samples_left < 0:
            self.halt_nm = math.nan
            return False
        if value < self.max_nm - 0.5 * self.drop_nm and target_torque_nm:
            # slipped: the plan was for the phase that just ended; until the
            # event is confirmed and a new plan made, this phase halts on target
            self.halt_nm = target_torque_nm
            self.max_nm = value
        return True


class TargetRule:
    """target_reached: three samples over the target, the ramp's projection, or the halt plan."""

    __slots__ = (
        "_lead_samples",
        "_over_target",
        "_previous_value",
        "_project",
        "_ramp",
        "halt",
        "target_force_n",
        "target_torque_nm",
    )

    def __init__(self, settings: PredictorSettings) -> None:
        s = settings
        self.target_force_n = s.target_force_n if s.has_force else None
        self.target_torque_nm = s.target_torque_nm if self.target_force_n is None else None
        self.halt = HaltPlan()
        self._ramp = RampEstimator()
        self._lead_samples = s.reaction_samples + 0.5
        # a torque target reached in a final stage is decided on the stage's line
        # (final_stage_run): the projection of a noisy slow ramp would halt early
        self._project = s.final_stage is None or self.target_torque_nm is None
        self._over_target = 0
        self._previous_value = math.nan

    def check(self, torque_nm: float, force_n: float | None) -> Stop | None:
        """One sample; ``force_n`` None: no force yet in this run, a force target waits."""
        if self.target_force_n is not None:
            if force_n is None:
                return None
            value, target, quantity, unit = force_n, self.target_force_n, "force", "N"
        elif self.target_torque_nm is not None:
            value, target, quantity, unit = torque_nm, self.target_torque_nm, "torque", "Nm"
        else:
            return None
        self._ramp.add(value)
        self._over_target = self._over_target + 1 if value >= target else 0
        previous, self._previous_value = self._previous_value, value
        halt = self.halt
        if self.target_torque_nm is not None and halt.holds(value, self.target_torque_nm):
            # one spike is not a reason: the torque now is taken as at most two
            # ramp steps above the sample before
            now = value if math.isnan(previous) else min(value, previous + 2.0 * halt.rate_nm)
            at_halt = now + halt.rate_nm * self._lead_samples
            if at_halt < halt.halt_nm:
                return None
            return Stop(
                "target_reached",
                f"{quantity} {value:.5g} {unit} + ramp: {at_halt:.5g} {unit} at the halt ≥ "
                f"planned {halt.halt_nm:.5g} {unit} (target {target:g} {unit}, slip risk)",
                at_halt,
            )
        if self._over_target >= TARGET_SAMPLES:
            return Stop(
                "target_reached", f"{quantity} {value:.5g} {unit} ≥ target {target:g} {unit}"
            )
        projected = self._ramp.projected(self._lead_samples) if self._project else math.nan
        if projected >= target:
            return Stop(
                "target_reached",
                f"{quantity} ramp projected to {projected:.5g} {unit} at the halt "
                f"≥ target {target:g} {unit}",
                projected,
            )
        return None
