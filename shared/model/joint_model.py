"""One joint at one motor speed: every bound of the paper's model over model time t.

``JointModel(constants, motor_speed_rad_s)`` gathers the functions of
:mod:`angles` (eqs. 15-20), :mod:`slip_bounds` (21-26), :mod:`timing`
(27-29) and :mod:`characteristic_constants` (31-39). Methods take model time
``t`` in seconds (float or numpy array), with φ_m = φ̇_m · t from the
untwisted, unloaded joint; use :meth:`JointModel.time_at_force_s` to evaluate
"at the target". ``relief_fraction`` ρ < 1 gives the paper's partial-relief
variant (dashed lines of Figures 13-15): every slip-sized quantity (Δφ_b,
φ_0,stick, ΔT, ΔF) times ρ, every frequency divided by ρ.

Envelope lines of the torque and preload traces (Figure 10): a slip starts
when T = φ_0,stick · k_e (eqs. 9, 19) with F = k_s · φ_b,min; it ends at the
latest with T = 0 and at the earliest with T = φ_0,slip · k_e, F = k_s · φ_b,max.
"""

from __future__ import annotations

from dataclasses import dataclass

from shared.model import angles, slip_bounds, timing
from shared.model.angles import Value
from shared.model.characteristic_constants import ConstantBands, expected_constant_bands
from shared.model.slip_bounds import FULL_RELIEF
from shared.model.stiffness import JointConstants


@dataclass(frozen=True, slots=True)
class JointModel:
    """The analytical model of one joint tightened at a constant motor speed."""

    constants: JointConstants
    motor_speed_rad_s: float
    relief_fraction: float = FULL_RELIEF

    def __post_init__(self) -> None:
        if self.motor_speed_rad_s <= 0.0:
            raise ValueError(f"motor_speed_rad_s must be positive (got {self.motor_speed_rad_s})")
        if not 0.0 < self.relief_fraction <= 1.0:
            raise ValueError(f"relief_fraction must be in (0, 1] (got {self.relief_fraction})")

    def with_relief(self, relief_fraction: float) -> JointModel:
        """The same joint with slips releasing only ``relief_fraction`` of the full model."""
        return JointModel(self.constants, self.motor_speed_rad_s, relief_fraction)

    # --- constants of the joint --------------------------------------------------

    @property
    def gamma_stick(self) -> float:
        """γ_stick, eq. 16."""
        c = self.constants
        return angles.angle_ratio(c.k_e_nm_per_rad, c.k_s_n_per_rad, c.r_m, c.mu_stick)

    @property
    def gamma_slip(self) -> float:
        """γ_slip, eq. 17."""
        c = self.constants
        return angles.angle_ratio(c.k_e_nm_per_rad, c.k_s_n_per_rad, c.r_m, c.mu_slip)

    def constant_bands(self) -> ConstantBands:
        """Expected K1-K3 bands, eqs. 34-39."""
        return expected_constant_bands(self.constants, self.motor_speed_rad_s, self.relief_fraction)

    # --- angles over t (eqs. 15-20) ----------------------------------------------

    def motor_angle_rad(self, time_s: Value) -> Value:
        """φ_m = φ̇_m · t, rad."""
        return time_s * self.motor_speed_rad_s

    def bearing_angle_min_rad(self, time_s: Value) -> Value:
        """φ_b,min, eq. 16."""
        return angles.bearing_angle_min_rad(self.motor_angle_rad(time_s), self.gamma_stick)

    def bearing_angle_max_rad(self, time_s: Value) -> Value:
        """φ_b,max, eq. 17."""
        return angles.bearing_angle_max_rad(self.motor_angle_rad(time_s), self.gamma_slip)

    def slip_angle_rad(self, time_s: Value) -> Value:
        """ρ · Δφ_b, eq. 18."""
        phi_m = self.motor_angle_rad(time_s)
        slip = angles.slip_angle_rad(phi_m, self.gamma_stick, self.gamma_slip)
        return slip * self.relief_fraction

    def twist_at_stick_rad(self, time_s: Value) -> Value:
        """ρ · φ_0,stick, eq. 19 (the largest slip)."""
        phi_m = self.motor_angle_rad(time_s)
        return angles.twist_at_stick_rad(phi_m, self.gamma_stick) * self.relief_fraction

    # --- event bounds over t (eqs. 21-26) ----------------------------------------

    def torque_drop_min_nm(self, time_s: Value) -> Value:
        """ΔT_min, eq. 21."""
        return self.slip_angle_rad(time_s) * self.constants.k_e_nm_per_rad

    def torque_drop_max_nm(self, time_s: Value) -> Value:
        """ΔT_max, eq. 22."""
        return self.twist_at_stick_rad(time_s) * self.constants.k_e_nm_per_rad

    def force_step_min_n(self, time_s: Value) -> Value:
        """ΔF_min, eq. 23."""
        return self.slip_angle_rad(time_s) * self.constants.k_s_n_per_rad

    def force_step_max_n(self, time_s: Value) -> Value:
        """ΔF_max, eq. 24."""
        return self.twist_at_stick_rad(time_s) * self.constants.k_s_n_per_rad

    def stick_slip_frequency_min_hz(self, time_s: Value) -> Value:
        """f_ss,min, eq. 25 (divided by ρ)."""
        f_hz = slip_bounds.stick_slip_frequency_min_hz(time_s, self.gamma_stick)
        return f_hz / self.relief_fraction

    def stick_slip_frequency_max_hz(self, time_s: Value) -> Value:
        """f_ss,max, eq. 26 (divided by ρ)."""
        f_hz = slip_bounds.stick_slip_frequency_max_hz(time_s, self.gamma_stick, self.gamma_slip)
        return f_hz / self.relief_fraction

    # --- trace envelopes (Figure 10) ---------------------------------------------

    def peak_torque_nm(self, time_s: Value) -> Value:
        """T_stick = φ_0,stick · k_e: the torque at which sticking breaks (eqs. 9, 19)."""
        phi_m = self.motor_angle_rad(time_s)
        twist = angles.twist_at_stick_rad(phi_m, self.gamma_stick)
        return twist * self.constants.k_e_nm_per_rad

    def slip_torque_nm(self, time_s: Value) -> Value:
        """T_slip = φ_0,slip · k_e: the torque where the smallest slip ends (eqs. 10, 20)."""
        phi_m = self.motor_angle_rad(time_s)
        twist = angles.twist_at_slip_rad(phi_m, self.gamma_slip)
        return twist * self.constants.k_e_nm_per_rad

    def force_at_stick_n(self, time_s: Value) -> Value:
        """k_s · φ_b,min: the preload plateau when sticking breaks (eqs. 8, 16)."""
        return self.bearing_angle_min_rad(time_s) * self.constants.k_s_n_per_rad

    def force_at_slip_n(self, time_s: Value) -> Value:
        """k_s · φ_b,max: the preload after the smallest slip (eqs. 8, 17)."""
        return self.bearing_angle_max_rad(time_s) * self.constants.k_s_n_per_rad

    # --- time (eqs. 27-29) ----------------------------------------------------

    def time_at_force_s(self, force_n: Value, *, at_slip: bool = False) -> Value:
        """Model time at which the preload plateau F is left (sticking breaks), s.

        ``at_slip=True``: the time at which a smallest slip comes to rest at F.
        """
        gamma = self.gamma_slip if at_slip else self.gamma_stick
        return timing.time_at_force_s(
            force_n, self.motor_speed_rad_s, self.constants.k_s_n_per_rad, gamma
        )

    def time_at_torque_s(self, torque_nm: Value) -> Value:
        """Model time at which the peak torque (sticking breaks) reaches T, s."""
        return timing.time_at_torque_s(
            torque_nm, self.motor_speed_rad_s, self.constants.k_e_nm_per_rad, self.gamma_stick
        )

    def total_time_s(self, target_torque_nm: float, target_force_n: float) -> float:
        """t_total = t_e + t_screw for independently given targets, s (eqs. 27-29)."""
        return timing.total_time_s(
            target_torque_nm,
            target_force_n,
            self.motor_speed_rad_s,
            self.constants.k_e_nm_per_rad,
            self.constants.k_s_n_per_rad,
        )
