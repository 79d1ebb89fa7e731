"""What one run is predicted against: targets, limits, window and thresholds.

Built from the station's :class:`~shared.config.Program` and
:class:`~shared.config.PredictorSection` with :meth:`PredictorSettings.of`, or
directly (``boltwatch predict``, tests, benchmarks). The default window, n = 5
samples of eqs. 43-45, serves stick-slip up to about 150 Hz at 1 kHz; a
station whose stick-slip is known to be slow may raise it
(``predictor.window_samples``). Why 5, measured against the rig's true slips:
``docs/explanation/algorithm.md``, "Why the window is 5 samples".
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from shared.config import FinalStage, PredictorSection, Program
from shared.contract import CONTRACT_RANGE, SensorRange, ToolCommandsName
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
    # the step the recorded torque is written to (Nm; 0: not known): a drop of no more than
    # a few steps is no slip (see signal_resolution)
    torque_resolution_nm: float = 0.0
    # the program's final stage, when the tool runs it (its controller takes StageCommand):
    # the core then also commands the switch, the pulses and the finish (final_stage_run)
    final_stage: FinalStage | None = None

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
        commands: ToolCommandsName = "stop",
    ) -> PredictorSettings:
        """Settings for a run of ``program`` on a station with (or without) a force sensor;
        ``commands="staged"``: its tool runs the program's final stage, if it has one."""
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
            final_stage=program.final_stage if commands == "staged" else None,
        )
