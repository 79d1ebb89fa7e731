"""One tightening as a hybrid stick-slip simulation (paper Fig. 1, eqs. 2-10). Pure.

The model of the paper's Figure 1: a motor turning at constant speed
φ̇_m = w, an extension of torsional stiffness k_e (eq. 2), and the screw with
socket (inertia J) whose angle φ_b sets the preload F = k_s · φ_b (eq. 8).
The torque in the extension, which the tool's transducer measures, is

    T = k_e (φ_m − φ_b)                                                (eqs. 9, 10)

STICK (eq. 9): the screw stands, φ̇_b = 0, while |T| ≤ μ_stick,j · F · r. The
state is exact: φ_b is constant and T grows linearly with time, so the
instant the stick breaks is solved for directly:

    k_e (φ_m + w s − φ_b) = μ_stick,j · k_s φ_b · r
    ->  s = (μ_stick,j · k_s · r · φ_b / k_e + φ_b − φ_m) / w

SLIP (eq. 10 with inertia): the screw slides forward; its motion is the closed
form of :mod:`services.rig.slip_oscillator`. The slip ends when φ̇_b returns
to 0 and the torque is within the (newly drawn) stick limit again; otherwise
it goes on. The zero of φ̇_b is found by scanning the closed form at 1/16 of
a half period and bisecting the bracketing step. A screw that would slide
backwards (T < −μ_stick F r) is not modelled: a tightening never gets there.

μ_stick,j scatters per stick phase: μ_stick · (1 + scatter · N(0, 1)), kept
above μ_slip. Friction draws and sensor noise come from two independent
generators spawned from one seed, so the j-th stick phase of a joint has the
same friction whether the tool stopped early or not (policies compare on
identical joints).

The run starts at F = start_force_n with the extension pre-twisted to the
slip torque, T = μ_slip F r, i.e. φ_m = φ_b / γ_slip (eq. 17): the motor
angle is absolute in the paper's sense, so the analytical bounds of eqs.
16-26 apply to it directly. The angle sensor reports φ_m since the run start.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from services.rig.slip_oscillator import SlipOscillator
from shared.config import Program, RigSection
from shared.model import JointConstants

NOISE_BLOCK_SAMPLES = 1024
SCAN_STEPS_PER_HALF_PERIOD = 16
BISECTION_STEPS = 40
#: μ_stick,j stays at least this fraction above μ_slip (clipping of the scatter)
MIN_STICK_MARGIN = 1e-3


@dataclass(frozen=True, slots=True)
class Measurement:
    """Noisy sensor values at the end of one sample period."""

    time_s: float
    torque_nm: float
    angle_deg: float
    force_n: float


class TighteningPhysics:
    """The joint, extension and motor of one tightening; ``advance()`` per sample."""

    def __init__(
        self,
        constants: JointConstants,
        program: Program,
        rig: RigSection,
        seed: int,
        sample_period_s: float = 1e-3,
    ) -> None:
        if sample_period_s <= 0:
            raise ValueError(f"sample_period_s must be positive (got {sample_period_s})")
        self._k_e = constants.k_e_nm_per_rad
        self._k_s = constants.k_s_n_per_rad
        self._r = constants.r_m
        self._mu_stick = constants.mu_stick
        self._mu_slip = constants.mu_slip
        self._scatter = rig.mu_stick_scatter
        self._oscillator = SlipOscillator.of(constants, rig.inertia_kg_m2, rig.damping_ratio)
        self._scan_step_s = self._oscillator.half_period_s / SCAN_STEPS_PER_HALF_PERIOD
        self._period_s = sample_period_s
        self._noise_sigma = np.array(
            [rig.torque_noise_nm, rig.angle_noise_deg, rig.force_noise_n], dtype=np.float64
        )
        friction_seed, noise_seed = np.random.SeedSequence(seed).spawn(2)
        self._friction_rng = np.random.default_rng(friction_seed)
        self._noise_rng = np.random.default_rng(noise_seed)
        self._noise_block = np.zeros((0, 3))
        self._noise_index = 0

        # Start: F = start_force_n, extension twisted to the slip torque (eq. 17).
        self._angle_b = program.start_force_n / self._k_s
        self._speed_b = 0.0
        self._motor_angle = self._angle_b + (
            self._mu_slip * program.start_force_n * self._r / self._k_e
        )
        self._motor_start = self._motor_angle
        self._motor_speed = program.motor_speed_rad_s
        self._samples = 0
        self._time_s = 0.0
        self._slipping = False
        self._slip_count = 0
        self._plateaus: list[float] = []
        self._stick_limit_mu = self._draw_mu_stick()
        self._plateaus.append(self.true_force_n)

    # --- state --------------------------------------------------------------

    @property
    def time_s(self) -> float:
        return self._time_s

    @property
    def motor_running(self) -> bool:
        return self._motor_speed > 0.0

    @property
    def slipping(self) -> bool:
        return self._slipping

    @property
    def settled(self) -> bool:
        """The motor is halted and no slip is under way: nothing will change any more."""
        return not self.motor_running and not self._slipping

    @property
    def true_force_n(self) -> float:
        return self._k_s * self._angle_b

    @property
    def true_torque_nm(self) -> float:
        return self._k_e * (self._motor_angle - self._angle_b)

    @property
    def motor_angle_rad(self) -> float:
        """φ_m in the paper's absolute sense (zero where F = 0 and T = 0)."""
        return self._motor_angle

    @property
    def slip_count(self) -> int:
        return self._slip_count

    @property
    def plateau_forces_n(self) -> list[float]:
        """True preload of every stick phase so far, in order (the first is the start)."""
        return list(self._plateaus)

    # --- commands -------------------------------------------------------------

    @property
    def motor_speed_rad_s(self) -> float:
        """φ̇_m now: the program's speed, a final stage's, or 0 once halted."""
        return self._motor_speed

    def halt_motor(self) -> None:
        """The motor stops now; a slip under way finishes by itself."""
        self._motor_speed = 0.0

    def set_motor_speed(self, speed_rad_s: float) -> None:
        """The motor turns at ``speed_rad_s`` from now on (a final stage, a pulse; 0 halts).

        The state stays exact across the change: a stick phase goes on standing
        with the torque now rising at k_e · speed (its break instant is solved
        again at the next :meth:`advance`), a slip under way goes on with the
        motor's new speed in its closed form.
        """
        if not speed_rad_s >= 0.0 or math.isinf(speed_rad_s):
            raise ValueError(f"speed_rad_s must be finite and ≥ 0 (got {speed_rad_s})")
        self._motor_speed = speed_rad_s

    def advance(self) -> Measurement:
        """One sample period forward; the (noisy) sensors at its end."""
        self._samples += 1
        end_s = self._samples * self._period_s
        remaining_s = end_s - self._time_s
        while remaining_s > 0.0:
            if self._slipping:
                remaining_s -= self._slide(remaining_s)
            else:
                remaining_s -= self._stick(remaining_s)
        self._time_s = end_s
        return self._measure()

    # --- phases ---------------------------------------------------------------

    def _stick(self, budget_s: float) -> float:
        """Stand still up to ``budget_s``; start a slip when the stick limit is reached."""
        speed = self._motor_speed
        if speed > 0.0:
            limit_twist = self._stick_limit_mu * self._k_s * self._r * self._angle_b / self._k_e
            break_s = max(0.0, (limit_twist + self._angle_b - self._motor_angle) / speed)
            if break_s < budget_s:
                self._motor_angle += speed * break_s
                self._time_s += break_s
                self._slipping = True
                self._slip_count += 1
                return break_s
        self._motor_angle += speed * budget_s
        self._time_s += budget_s
        return budget_s

    def _slide(self, budget_s: float) -> float:
        """Slide up to ``budget_s`` or until φ̇_b returns to 0; the time used."""
        end_s = self._find_stop(budget_s)
        used_s = budget_s if end_s is None else end_s
        angle, speed = self._oscillator.state_after(
            self._angle_b, self._speed_b, self._motor_angle, self._motor_speed, used_s
        )
        self._angle_b = angle
        self._motor_angle += self._motor_speed * used_s
        self._time_s += used_s
        if end_s is None:
            self._speed_b = speed
            return used_s
        self._speed_b = 0.0
        self._stick_limit_mu = self._draw_mu_stick()
        if self.true_torque_nm <= self._stick_limit_mu * self.true_force_n * self._r:
            self._slipping = False
            self._plateaus.append(self.true_force_n)
        return used_s

    def _find_stop(self, budget_s: float) -> float | None:
        """Time from now at which φ̇_b first returns to 0 within ``budget_s``, if it does."""
        if self._speed_b <= 0.0 and self._acceleration() < 0.0:
            return 0.0
        low_s = 0.0
        while low_s < budget_s:
            high_s = min(low_s + self._scan_step_s, budget_s)
            if self._speed_at(high_s) <= 0.0:
                return self._bisect(low_s, high_s)
            low_s = high_s
        return None

    def _bisect(self, low_s: float, high_s: float) -> float:
        """Narrow [low, high] (speed > 0 at low, ≤ 0 at high) to the zero; returns high."""
        for _ in range(BISECTION_STEPS):
            middle_s = 0.5 * (low_s + high_s)
            if self._speed_at(middle_s) > 0.0:
                low_s = middle_s
            else:
                high_s = middle_s
        return high_s

    def _speed_at(self, elapsed_s: float) -> float:
        return self._oscillator.state_after(
            self._angle_b, self._speed_b, self._motor_angle, self._motor_speed, elapsed_s
        )[1]

    def _acceleration(self) -> float:
        """φ̈_b while sliding forward (eq. 10 with inertia and damping), rad/s²."""
        friction_nm = self._mu_slip * self.true_force_n * self._r
        damping_nm = self._oscillator.damping_nm_s_per_rad * self._speed_b
        return (self.true_torque_nm - friction_nm - damping_nm) / self._oscillator.inertia_kg_m2

    def _draw_mu_stick(self) -> float:
        """μ_stick,j of the next stick phase, scattered and kept above μ_slip."""
        draw = float(self._friction_rng.standard_normal())
        mu = self._mu_stick * (1.0 + self._scatter * draw)
        return max(mu, self._mu_slip * (1.0 + MIN_STICK_MARGIN))

    # --- sensors --------------------------------------------------------------

    def _measure(self) -> Measurement:
        if self._noise_index >= len(self._noise_block):
            self._noise_block = self._noise_rng.standard_normal((NOISE_BLOCK_SAMPLES, 3))
            self._noise_block *= self._noise_sigma
            self._noise_index = 0
        torque_noise, angle_noise, force_noise = self._noise_block[self._noise_index]
        self._noise_index += 1
        return Measurement(
            time_s=self._time_s,
            torque_nm=self.true_torque_nm + float(torque_noise),
            angle_deg=math.degrees(self._motor_angle - self._motor_start) + float(angle_noise),
            force_n=self.true_force_n + float(force_noise),
        )
