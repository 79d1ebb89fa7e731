"""When to stop the tool, and why (paper Sec. 6.6 and the program's hard limits).

The rules, one class each in :mod:`.stop_rules`, in the order they are checked:

On every sample (O(1)):

1. :class:`~.stop_rules.hard_limits.HardLimits`: torque_limit, force_limit,
   angle_limit, each held for ``limit_samples`` samples in a row;
2. :class:`~.stop_rules.target_rule.TargetRule`: target_reached, with the
   torque halt plan of :meth:`StopPolicy.plan_halt`.

Once per stick-slip event j (after its slip, on the new plateau):

3. :class:`~.stop_rules.intensity_rule.IntensityRule`: intensity_limit, eq. 70;
4. :class:`~.stop_rules.constant_band_rule.ConstantBandRule`: constant_out_of_band,
   eq. 71 (the model's band, then the running means);
5. :class:`~.stop_rules.plateau_rule.PlateauRule`: plateau_closest, eqs. 64/65.

The limits and the wear rules (3, 4) come before the plateau choice: a
joint out of its band or a tool over its intensity budget is stopped even
when the next plateau would be closer. The first decision is latched: one
decision per run; an input fault (the core's input guard) is one more reason.
"""

from __future__ import annotations

import math

from shared.stickslip.model_bands import BandVerdict
from shared.stickslip.outputs import CoreDecision
from shared.stickslip.settings import PredictorSettings
from shared.stickslip.stop_rules.constant_band_rule import ConstantBandRule
from shared.stickslip.stop_rules.hard_limits import HardLimits
from shared.stickslip.stop_rules.intensity_rule import IntensityRule
from shared.stickslip.stop_rules.plateau_rule import PlateauRule
from shared.stickslip.stop_rules.stop import Stop
from shared.stickslip.stop_rules.target_rule import TargetRule


class StopPolicy:
    """The per-sample and per-event stop rules, in order, with a latch."""

    def __init__(self, settings: PredictorSettings) -> None:
        self.settings = settings
        self.decision: CoreDecision | None = None
        self.limits = HardLimits(settings)
        self.target = TargetRule(settings)
        self.intensity = IntensityRule(settings.max_process_intensity)
        self.constant_bands = ConstantBandRule(settings.constant_band, settings.constant_window)
        self.plateau = PlateauRule(self.target.target_force_n, self.target.target_torque_nm)

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
        self.target.halt.plan(
            halt_nm, rate_nm_per_sample, drop_nm, valid_samples, self.limits.max_torque_nm
        )

    def on_sample(
        self, time_s: float, torque_nm: float, force_n: float | None, turned_deg: float
    ) -> CoreDecision | None:
        """Rules 1 and 2; None to go on.

        ``force_n`` None: the sample has no force (none measured yet in this run),
        so the force rules wait for one.
        """
        if self.decision is not None:
            return None
        stop = self.limits.check(torque_nm, force_n, turned_deg) or self.target.check(
            torque_nm, force_n
        )
        return None if stop is None else self._decide(time_s, stop, torque_nm, force_n)

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
        """Rules 3 to 5, after each event's slip (eqs. 70, 71, 64/65)."""
        if self.decision is not None:
            return None
        stop = (
            self.intensity.check(process_intensity)
            or self.constant_bands.check(constants, band_verdict)
            or self.plateau.check(force_now_n, force_next_n, peak_now_nm, peak_next_nm)
        )
        return None if stop is None else self._decide(time_s, stop, torque_nm, force_now_n)

    def on_final_stage(
        self, time_s: float, stop: Stop, torque_nm: float, force_n: float | None
    ) -> CoreDecision | None:
        """The final stage's halt on the target (:mod:`.final_stage_run`), if nothing
        decided before it."""
        if self.decision is not None:
            return None
        return self._decide(time_s, stop, torque_nm, force_n)

    def on_input_fault(self, time_s: float, bad_samples: int) -> CoreDecision | None:
        """The input guard saw ``bad_samples`` unusable samples in a row."""
        if self.decision is not None:
            return None
        stop = Stop("input_fault", f"{bad_samples} unusable samples in a row")
        return self._decide(time_s, stop, math.nan, None)

    def _decide(
        self, time_s: float, stop: Stop, torque_nm: float, force_n: float | None
    ) -> CoreDecision:
        force_target = self.target.target_force_n is not None
        self.decision = CoreDecision(
            time_s=time_s,
            reason=stop.reason,
            detail=stop.detail,
            torque_nm=torque_nm,
            force_n=force_n,
            # what the rule predicted the stop lands on: force when the target is a force
            predicted_force_n=stop.predicted if force_target else None,
            predicted_torque_nm=stop.predicted if not force_target else None,
        )
        return self.decision
