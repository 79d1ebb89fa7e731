"""What one run is predicted against: targets, limits, window and thresholds.

Built from the station's :class:`~shared.config.Program` and
:class:`~shared.config.PredictorSection` with :meth:`PredictorSettings.of`, or
directly (``boltwatch predict``, tests, benchmarks).

Why the default window is 5 samples (n of eqs. 43-45)
-------------------------------------------------------
With even sampling the sum of slopes of eq. 46 telescopes:
S = Σ ΔT_i/Δt = (T_newest - T_oldest)/Δt, so the inclination sign compares the
newest sample with the one n-1 samples back. A maximum is seen only if the
slip's drop outweighs the stick ramp over the rest of that span: with the
paper's n = 10-20 the detector is blind above 50-100 Hz. At the slow end
(10 Hz, 100 samples per tooth) a short window is noisy, so a flip alone is
not an event: the slip must also drop the torque by more than the noise
floor (see :mod:`.extremum_tracker`).

What n = 5 covers, measured against the rig's true slips
(``tests/benchmarks/bench_event_detection.py``, the 100 joints of the
accuracy benchmark run without a stop, 7901 slips: median 53 Hz, p95
250 Hz, max 500 Hz; a slip counts as found when an event's peak is within 5
samples of its break): recall 97.8 % below 50 Hz, 94.9 % at 50-100 Hz,
83.1 % at 100-150 Hz, 44 % at 150-200 Hz, 9 % at 200-300 Hz and 0 % above;
84.7 % overall, with 46 events matching no true slip (of 6735). (Before the
noise estimate was seeded from 32 samples: 85.4 %, 47 of 6796; the extra
0.7 % were fast slips at the start of a run, caught while the estimate sat
far below the noise, the same low floor that let noise wiggles through.) So the
default window serves stick-slip up to about 150 Hz; above, most slips are
lost, whatever n:

- their drops are small: of the 323 slips missed at 200-300 Hz, 203 drop
  the true torque by less than the floor the tracker would have on noise
  alone (3 · 1.65 σ ≈ 1 Nm for the rig's 0.2 Nm), indistinguishable from
  noise without false events;
- a slip whose drop is under the ramp's rise over the rest of the window
  span never turns the sign (257 of those 323 at n = 5; at n = 3, 129 of
  315, but they then fall under the noise floor instead: recall 85.5 %, no
  better, measured with the former one-sample noise start-up);
- at 1 kHz a 500 Hz slip is two samples, a rising zig-zag whose sign stays
  positive for any n ≥ 3;
- the noise floor itself rises with the rate of kinks (median 1.0 Nm below
  50 Hz, 2.8 Nm at 200-300 Hz): the median |second difference| then sees
  the slips, not only the noise.

Lowering the floor's factor from 3 to 2.5 finds 88.0 % but with 218 false
events (4.6 times more); n = 3 changes neither recall nor the stop
accuracy (force 0.49 %, torque-only 0.43 %, as with n = 5), n = 4 is worse
on force (0.53 %). A period of about twice the predicted one is no sign of
a missed slip either (at ≥ 1.8 ×, 45 % of such periods hide one), so it is
not counted. A station whose stick-slip is known to be slow may raise n
(``predictor.window_samples``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from shared.config import PredictorSection, Program
from shared.contract import CONTRACT_RANGE, SensorRange
from shared.model import JointConstants

DEFAULT_WINDOW_SAMPLES = 5

PlateauMethod = Literal["poly2", "linear", "mean_step"]


@dataclass(frozen=True, slots=True)
class PredictorSettings:
    """Everything the core needs for one run; None disables the check that uses it."""

    target_force_n: float | None = None
    target_torque_nm: float | None = None
    has_force: bool = True
    window_samples: int = DEFAULT_WINDOW_SAMPLES
    max_process_intensity: float | None = None  # I_max, eq. 70
    constant_band: float | None = None  # S_i of eq. 71, fraction of the running mean
    constant_window: int = 5  # n_K of eq. 71
    max_torque_nm: float | None = None
    max_force_n: float | None = None
    max_angle_deg: float | None = None  # of the angle turned since the run's first sample
    motor_speed_rad_s: float | None = None  # φ̇_m of eqs. 32-33; None: measured from the angle
    plateau_method: PlateauMethod = "poly2"
    fault_samples: int = 100  # consecutive unusable samples before input_fault
    limit_samples: int = 2  # consecutive samples beyond a hard limit before stopping
    reaction_samples: float = 1.0  # samples the motor still turns after the deciding sample
    constants: JointConstants | None = None  # the expected joint, when one is configured
    # torque target: also stop on the peak-torque plateau rule of eq. 64 (see stop_policy)
    torque_plateau_rule: bool = False
    # the decision does not stop the tool (a run replayed after a controller stopped it):
    # events go on being reported after it; otherwise none is reported after the decision
    advisory: bool = False
    # what the sensors can measure: a value outside is bad input (see input_guard)
    sensor_range: SensorRange = CONTRACT_RANGE

    @property
    def force_mode(self) -> bool:
        """True: decide on force plateaus (eq. 65); False: on peak torques (eq. 64)."""
        return self.has_force and self.target_force_n is not None

    @classmethod
    def of(
        cls,
        program: Program,
        section: PredictorSection,
        has_force: bool,
        constants: JointConstants | None = None,
        sensor_range: SensorRange = CONTRACT_RANGE,
    ) -> PredictorSettings:
        """Settings for a run of ``program`` on a station with (or without) a force sensor."""
        return cls(
            target_force_n=program.target_force_n,
            target_torque_nm=program.target_torque_nm,
            has_force=has_force,
            window_samples=section.window_samples,
            max_process_intensity=section.max_process_intensity,
            constant_band=section.constant_band,
            constant_window=section.constant_window,
            max_torque_nm=program.max_torque_nm,
            max_force_n=program.max_force_n if has_force else None,
            max_angle_deg=program.max_angle_deg,
            motor_speed_rad_s=program.motor_speed_rad_s,
            constants=constants,
            sensor_range=sensor_range,
        )
