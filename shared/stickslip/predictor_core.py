"""The predictor core: one object per run, fed sample by sample (paper Fig. 16).

::

    core = PredictorCore(settings)
    for t, torque, force, angle in samples:          # force NaN when there is none
        for output in core.update(t, torque, force, angle):
            ...                       # EventFigures, CoreDecision, or a final stage's CoreCommand

Per sample the work is O(1): the input guard, the window's running
inclination sum (eqs. 46, 47), a noise estimate, a running force sum and the
per-sample stop rules. Per event (tens of ms apart): the extremes of the
window (eqs. 48-51), the event's figures, the fits and predictions
(eqs. 52-56), the scores of past predictions (eqs. 57-63) and the per-event
stop rules (eqs. 64, 65, 70, 71).
"""

from __future__ import annotations

import logging
import math

from shared.contract import Prediction
from shared.stickslip.event_figures import EventFigures, compute_figures, event_period_s
from shared.stickslip.event_history import EventHistory
from shared.stickslip.extremum_tracker import ExtremumTracker, Slip
from shared.stickslip.final_stage_run import D2_PER_SIGMA, FinalStageRun
from shared.stickslip.force_history import ForceHistory
from shared.stickslip.halt_planner import HaltPlanner
from shared.stickslip.inclination_window import NO_FLIP, InclinationWindow
from shared.stickslip.input_guard import (
    DROP,
    HOLD,
    USE,
    USE_HELD,
    GuardedSample,
    InputGuard,
    InputReport,
)
from shared.stickslip.model_bands import BandVerdict, ModelBandCheck
from shared.stickslip.motor_motion import MotorMotion
from shared.stickslip.outputs import CoreCommand, CoreDecision
from shared.stickslip.regression import predict_events
from shared.stickslip.scoring import PredictionScores
from shared.stickslip.screw_plateaus import ScrewPlateaus
from shared.stickslip.settings import PredictorSettings
from shared.stickslip.stop_policy import StopPolicy

LOG = logging.getLogger(__name__)

FIRST_PLATEAU_SAMPLES = 20  # stick samples looked at for the first event's plateau

#: eq. 64 on torque peaks needs regular stick-slip: this many youngest peaks rising one
#: after the other (or, with plateaus from the screw angle, this many events). Wiggles of a
#: joint without stick-slip (thread forming, noise) also make events now and then; their
#: predicted peaks are no ground to stop on.
STAIRCASE_EVENTS = 3
PLAN_PERIODS = 1.5  # a torque halt plan holds this many predicted periods after its peak
MAX_STEP_FRACTION = 0.25  # a predicted step larger than this share of the value: no decision

CoreOutput = EventFigures | CoreDecision | CoreCommand


class PredictorCore:
    """Samples in, stick-slip events and (at most one) stop decision out."""

    def __init__(self, settings: PredictorSettings) -> None:
        self.settings = settings
        self._guard = InputGuard(settings.has_force, settings.sensor_range)
        self._window = InclinationWindow(settings.window_samples)
        self._motion = MotorMotion()
        self._tracker = ExtremumTracker(self._motion, settings.torque_resolution_nm)
        self._add_torque_noise = self._tracker.torque_noise.add
        self._forces = ForceHistory()
        self._screw = ScrewPlateaus()
        self.policy = StopPolicy(settings)
        self.model_bands = (
            ModelBandCheck(settings.constants, settings.constant_window)
            if settings.constants is not None
            else None
        )
        self.scores = PredictionScores()
        target_torque = settings.target_torque_nm
        self._halt_planner = (
            HaltPlanner(target_torque)
            if not settings.force_mode and target_torque is not None and target_torque > 0.0
            else None
        )
        stage = settings.final_stage
        self.final_stage = (
            FinalStageRun(
                stage,
                None if settings.force_mode else target_torque,
                settings.target_force_n if settings.force_mode else None,
                settings.reaction_samples,
            )
            if stage is not None
            else None
        )
        constants, speed = settings.constants, settings.motor_speed_rad_s
        self._model_ramp_nm_per_s = (  # k_e · φ̇_m: the joint model's stick ramp
            constants.k_e_nm_per_rad * speed
            if constants is not None and speed is not None
            else math.nan
        )
        self._count = 0
        self._start_time_s = math.nan
        self._start_angle_deg = math.nan
        self.history = EventHistory()
        self.events = 0
        self.process_intensity = 0.0

    @property
    def input_report(self) -> InputReport:
        """What the input guard did with bad input so far."""
        return self._guard.report

    @property
    def halt_planner(self) -> HaltPlanner | None:
        """The torque halt planner (torque target without force), else None."""
        return self._halt_planner

    @property
    def decision(self) -> CoreDecision | None:
        """The run's latched stop decision, if any."""
        return self.policy.decision

    def on_tool_halted(self) -> None:
        """The tool reports it halted by itself (its own shutoff): a final stage then waits
        for the torque to settle and judges it as after its own halt."""
        if self.final_stage is not None:
            self.final_stage.on_tool_halted()

    def update(
        self, time_s: float, torque_nm: float, force_n: float, angle_deg: float
    ) -> list[CoreOutput]:
        """Feed one sample (force NaN when none); the events and decision it produced.

        Whatever the values, only what :mod:`.input_guard` lets through, made
        finite, reaches the rest of the core.
        """
        guard = self._guard
        code = guard.check(time_s, torque_nm, force_n, angle_deg)
        if code == USE:
            return self._use(guard.sample)
        if code == DROP:
            if guard.bad_run >= self.settings.fault_samples:
                fault = self.policy.on_input_fault(time_s, guard.bad_run)
                if fault is not None:
                    return [fault]
            return []
        if code == HOLD:
            return []
        out = self._use(guard.confirmed)  # a gap (or the run's first sample) confirmed
        if code == USE_HELD:
            out += self._use(guard.sample)
        return out  # USE_HELD_HOLD: this sample is held in turn

    def _use(self, sample: GuardedSample) -> list[CoreOutput]:
        time_s, torque_nm, force, angle_deg, angle_measured, force_measured = sample
        index = self._count
        self._count = index + 1
        if index == 0:
            self._start_time_s = time_s
            self._start_angle_deg = angle_deg
        self._forces.add(force if force_measured else None)
        self._motion.add(time_s, angle_deg, angle_measured)
        self._add_torque_noise(torque_nm)
        out: list[CoreOutput] = []
        flip = self._window.push(index, time_s, torque_nm, angle_deg, self._guard.nominal_dt_s)
        if flip != NO_FLIP:
            slip = self._tracker.on_flip(flip, self._window)
            if slip is not None and (self.settings.advisory or self.policy.decision is None):
                # after a binding decision the tool is being stopped: what follows is the
                # motor halting and the joint unloading, not stick-slip
                out.extend(self._on_slip(slip, time_s, torque_nm))
        decision = self.policy.on_sample(
            time_s, torque_nm, force, angle_deg - self._start_angle_deg
        )
        if decision is not None:
            out.append(decision)
        final = self.final_stage
        if final is not None:
            if decision is not None:
                final.on_decided(decision.reason)
            else:
                out.extend(self._final_stage(final, time_s, torque_nm, force))
        return out

    def _final_stage(
        self, final: FinalStageRun, time_s: float, torque_nm: float, force: float | None
    ) -> list[CoreOutput]:
        """The final stage's command for this sample, or its first halt (a decision)."""
        planner = self._halt_planner
        drop_nm = planner.drop_nm if planner is not None else math.nan
        step_nm = planner.rate_nm_per_sample if planner is not None else math.nan
        if not step_nm > 0.0:
            step_nm = self._model_ramp_nm_per_s * self._guard.nominal_dt_s
        sigma_nm = self._tracker.noise_d2_nm / D2_PER_SIGMA
        said = final.on_sample(time_s, torque_nm, step_nm, sigma_nm, drop_nm)
        if said is None:
            return []
        if isinstance(said, CoreCommand):
            return [said]
        decision = self.policy.on_final_stage(time_s, said, torque_nm, force)
        if decision is None:
            return []
        final.on_decided(decision.reason)
        return [decision]

    def _on_slip(self, slip: Slip, now_s: float, torque_nm: float) -> list[CoreOutput]:
        settings = self.settings
        history = self.history
        peak, trough = slip.peak, slip.trough
        self.events += 1
        j = self.events
        previous_time = history.newest_time_s
        previous_plateau = history.newest_plateau_n
        previous_peak = history.newest_peak_nm
        plateau: float | None = None
        force_now: float | None = None
        if settings.has_force:
            trough_before = history.trough_index
            if trough_before < 0:
                trough_before = max(-1, peak.index - FIRST_PLATEAU_SAMPLES)
            plateau = self._forces.plateau_before(trough_before, peak.index)
            force_now = self._forces.plateau_after(trough.index)
        speed = settings.motor_speed_rad_s
        if speed is None and previous_time is not None and peak.time_s > previous_time:
            speed = math.radians(peak.angle_deg - history.peak_angle_deg) / (
                peak.time_s - previous_time
            )
        history.add(
            peak.time_s,
            event_period_s(peak.time_s, previous_time),
            peak.torque_nm,
            plateau,
            trough.index,
            peak.angle_deg,
        )
        predictions = predict_events(
            peak.time_s,
            history.periods_s,
            history.peaks_nm,
            history.plateaus_n,
            settings.plateau_method,
        )
        event = compute_figures(
            index=j,
            time_since_start_s=peak.time_s - self._start_time_s,
            peak_torque_nm=peak.torque_nm,
            min_torque_nm=trough.torque_nm,
            plateau_force_n=plateau,
            previous_time_s=previous_time,
            previous_plateau_n=previous_plateau,
            time_s=peak.time_s,
            motor_speed_rad_s=speed,
            process_intensity_before=self.process_intensity,
            current_force_n=force_now,
            detected_at_s=now_s,
            predictions=predictions,
        )
        self.process_intensity = event.process_intensity
        self.scores.score(
            j,
            peak.time_s,
            event.period_s,
            peak.torque_nm,
            plateau,
            previous_peak,
            event.force_step_n,
        )
        self.scores.remember(j, predictions)
        out: list[CoreOutput] = [event]
        if self._halt_planner is not None and self.policy.decision is None:
            halt = self._halt_planner.on_event(
                peak.index,
                peak.torque_nm,
                trough.index,
                trough.torque_nm,
                [p.peak_torque_nm for p in predictions],
            )
            planner = self._halt_planner
            valid = 0
            if predictions and self._guard.nominal_dt_s > 0.0:
                period_s = predictions[0].time_s - peak.time_s
                valid = int(PLAN_PERIODS * period_s / self._guard.nominal_dt_s) + 1
            if self.final_stage is None:  # a final stage halts on its own line
                self.policy.plan_halt(halt, planner.rate_nm_per_sample, planner.drop_nm, valid)
        verdict = None
        if self.model_bands is not None:
            verdict = self.model_bands.on_event(
                peak.torque_nm,
                event.torque_drop_nm,
                event.period_s,
                event.force_step_n,
                speed,
                self._tracker.noise_d2_nm,
                self._tracker.min_drop_nm(peak.torque_nm),
            )
        by_angle = None
        if not settings.force_mode:
            by_angle = self._screw.on_event(
                peak.angle_deg, peak.torque_nm, trough.angle_deg, trough.torque_nm
            )
        decision = self._decide_on_event(
            now_s,
            torque_nm,
            plateau,
            force_now,
            predictions,
            (event.k1, event.k2, event.k3),
            by_angle,
            verdict,
        )
        if decision is not None:
            out.append(decision)
            if self.final_stage is not None:
                self.final_stage.on_decided(decision.reason)
        return out

    def _decide_on_event(
        self,
        now_s: float,
        torque_nm: float,
        plateau: float | None,
        force_now: float | None,
        predictions: list[Prediction],
        constants: tuple[float | None, float | None, float | None],
        by_angle: tuple[float, float] | None = None,
        verdict: BandVerdict | None = None,
    ) -> CoreDecision | None:
        """The per-event stop rules, fed with plausible predictions only.

        Torque-only: the plateaus in torque units from the screw angle
        (:mod:`.screw_plateaus`) when there are enough events for them, else
        the line through the youngest peaks (Sec. 6.4).
        """
        force_next = None
        if force_now is not None:
            step = None
            if len(predictions) >= 2:
                p1, p2 = predictions[0].plateau_force_n, predictions[1].plateau_force_n
                if p1 is not None and p2 is not None and p2 > p1:
                    step = p2 - p1
            if step is None and plateau is not None and force_now > plateau:
                step = force_now - plateau  # the step just taken
            if step is not None and step <= MAX_STEP_FRACTION * abs(force_now):
                force_next = force_now + step
        peak_now = peak_next = None
        if not self.settings.torque_plateau_rule:
            pass
        elif by_angle is not None and self.history.has(STAIRCASE_EVENTS):
            now, after = by_angle
            if after - now <= MAX_STEP_FRACTION * now:
                peak_now, peak_next = now, after
        elif len(predictions) >= 2 and self.history.peaks_rise(STAIRCASE_EVENTS):
            now, after = predictions[0].peak_torque_nm, predictions[1].peak_torque_nm
            if 0.0 < after - now <= MAX_STEP_FRACTION * abs(now):
                peak_now, peak_next = now, after
        return self.policy.on_event(
            now_s,
            torque_nm,
            force_now,
            force_next,
            peak_now,
            peak_next,
            self.process_intensity,
            constants,
            verdict,
        )
