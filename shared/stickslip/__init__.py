"""The paper's stick-slip algorithm as a library: samples in, events and stop decisions out. Pure.

No zenoh, no clock: the same :class:`PredictorCore` serves the live service,
the acquisition's edge predictor, ``boltwatch predict``, ``boltwatch import``,
the Open Protocol bridge and the tests. Files, one concept each:

- :mod:`.settings`           what one run is predicted against (program, targets, limits)
- :mod:`.input_guard`        bad input (NaN, absurd values, bad times, gaps, lost frames) made safe
- :mod:`.inclination_window` the window of n samples and its mean inclination, eqs. 43-51
- :mod:`.second_difference`  a signal's noise: the running median of its |second difference|
- :mod:`.extremum_tracker`   maxima and minima paired into slips, with a noise floor
- :mod:`.signal_resolution`  the step a recorded signal is written to: a floor under a slip
- :mod:`.motor_motion`       did the motor drive through a drop (a slip) or not (a release, pause)
- :mod:`.force_history`      force sums per sample: the plateau of any stick phase in O(1)
- :mod:`.event_figures`      EventFigures: event j with ΔT, ΔF, Δt, f_ss, K1-K3, I_j, I_process
                             (eqs. 31-33, 66-68), what the core reports per event
- :mod:`.event_history`      the youngest events' times, periods, peaks and plateaus
- :mod:`.regression`         least-squares fits and next-event predictions (eqs. 52-56, 6.4)
- :mod:`.scoring`            errors of past predictions (eqs. 57-63)
- :mod:`.ramp_estimator`     where a steady ramp will be when the motor has stopped
- :mod:`.screw_plateaus`     torque-only plateaus from the screw angle (eqs. 8, 9)
- :mod:`.halt_planner`       torque-only: the halt torque of least expected error per stick phase
- :mod:`.model_bands`        eq. 71 against the band of the station's joint model (eqs. 34-39)
- :mod:`.stop_policy`        when to stop and why: the rules of :mod:`.stop_rules`, in order
- :mod:`.stop_rules`         one class per rule: hard limits, target and halt plan,
                             plateau (eqs. 64/65), intensity (eq. 70), constant bands (eq. 71)
- :mod:`.final_stage_run`    a final stage: when to slow down, halt, pulse, finish
- :mod:`.sliding_line`       a least-squares line through the newest samples, O(1)
- :mod:`.outputs`            the stop decision (CoreDecision), a final stage's CoreCommand
- :mod:`.predictor_core`     the facade that joins them
- :mod:`.run_messages`       the core's outputs as the messages a station publishes
- :mod:`.trace_replay`       the core over an offline trace (``boltwatch predict``)
- :mod:`.stopped_run`, :mod:`.advisory_replay`  the core over a run a tool controller
                             stopped, after the fact (``boltwatch import``, the bridge)
"""

from shared.stickslip.advisory_replay import replay_run
from shared.stickslip.event_figures import (
    EventFigures,
    compute_figures,
    event_intensity,
    torque_mean_nm,
)
from shared.stickslip.event_history import HISTORY, EventHistory
from shared.stickslip.extremum_tracker import NOISE_FACTOR, ExtremumTracker
from shared.stickslip.force_history import ForceHistory
from shared.stickslip.halt_planner import MIN_EVENTS, HaltPlanner, best_halt, expected_error
from shared.stickslip.inclination_window import MAX_PASSED, MIN_PASSED, NO_FLIP, InclinationWindow
from shared.stickslip.input_guard import InputReport
from shared.stickslip.model_bands import MIN_STICK_SHARE, MODEL_SLACK, ModelBandCheck
from shared.stickslip.motor_motion import MotorMotion
from shared.stickslip.outputs import CoreCommand, CoreDecision
from shared.stickslip.predictor_core import PredictorCore
from shared.stickslip.ramp_estimator import SPAN, RampEstimator
from shared.stickslip.regression import fit_line, fit_parabola, predict_periods, predict_plateaus
from shared.stickslip.run_messages import (
    decision_message,
    event_messages,
    stage_message,
    stick_slip_event,
)
from shared.stickslip.scoring import PredictionScores
from shared.stickslip.second_difference import SEED_SAMPLES
from shared.stickslip.settings import DEFAULT_WINDOW_SAMPLES, PlateauMethod, PredictorSettings
from shared.stickslip.signal_resolution import signal_resolution
from shared.stickslip.stop_policy import StopPolicy
from shared.stickslip.stopped_run import PredictorReplay, StoppedRun
from shared.stickslip.trace_replay import json_safe, output_record, replay

__all__ = [
    "DEFAULT_WINDOW_SAMPLES",
    "HISTORY",
    "MAX_PASSED",
    "MIN_EVENTS",
    "MIN_PASSED",
    "MIN_STICK_SHARE",
    "MODEL_SLACK",
    "NOISE_FACTOR",
    "NO_FLIP",
    "SEED_SAMPLES",
    "SPAN",
    "CoreCommand",
    "CoreDecision",
    "EventFigures",
    "EventHistory",
    "ExtremumTracker",
    "ForceHistory",
    "HaltPlanner",
    "InclinationWindow",
    "InputReport",
    "ModelBandCheck",
    "MotorMotion",
    "PlateauMethod",
    "PredictionScores",
    "PredictorCore",
    "PredictorReplay",
    "PredictorSettings",
    "RampEstimator",
    "StopPolicy",
    "StoppedRun",
    "best_halt",
    "compute_figures",
    "decision_message",
    "event_intensity",
    "event_messages",
    "expected_error",
    "fit_line",
    "fit_parabola",
    "json_safe",
    "output_record",
    "predict_periods",
    "predict_plateaus",
    "replay",
    "replay_run",
    "signal_resolution",
    "stage_message",
    "stick_slip_event",
    "torque_mean_nm",
]
