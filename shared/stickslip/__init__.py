"""The pure predictor core: samples in, stick-slip events and stop decisions out.

No zenoh, no clock: the same :class:`PredictorCore` serves the live service,
``boltwatch predict`` and the tests. Files, one concept each:

- :mod:`.settings`           what one run is predicted against (program, targets, limits)
- :mod:`.input_guard`        bad input (NaN, absurd values, bad times, gaps, lost frames) made safe
- :mod:`.inclination_window` the window of n samples and its mean inclination, eqs. 43-51
- :mod:`.second_difference`  a signal's noise: the running median of its |second difference|
- :mod:`.extremum_tracker`   maxima and minima paired into slips, with a noise floor
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
- :mod:`.outputs`            the stop decision: CoreDecision
- :mod:`.predictor_core`     the facade that joins them
"""

from shared.stickslip.event_figures import EventFigures
from shared.stickslip.outputs import CoreDecision
from shared.stickslip.predictor_core import PredictorCore
from shared.stickslip.settings import DEFAULT_WINDOW_SAMPLES, PredictorSettings

__all__ = [
    "DEFAULT_WINDOW_SAMPLES",
    "CoreDecision",
    "EventFigures",
    "PredictorCore",
    "PredictorSettings",
]
