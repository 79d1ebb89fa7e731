"""Bounds of one stick-slip event at model time t (paper eqs. 21-26, Section 5.3-5.5).

A slip turns the screw by some δ between the smallest slip Δφ_b (eq. 18:
it stops where sliding friction balances the extension) and the twist
φ_0,stick (eq. 19: it releases the whole extension). The torque in the
extension drops by k_e · δ and the preload rises by k_s · δ, hence

    ΔT_min = Δφ_b · k_e,        ΔT_max = φ_0,stick · k_e             (21, 22)
    ΔF_min = Δφ_b · k_s,        ΔF_max = φ_0,stick · k_s             (23, 24)

The paper takes the time to the next slip as the time the motor needs to
catch up with δ, Δt = δ / φ̇_m; with φ_m = φ̇_m · t and eqs. 18, 19:

    f_ss,min = φ̇_m / φ_0,stick = 1 / (t · (1 − γ_stick))            (25)
    f_ss,max = φ̇_m / Δφ_b = 1 / (t · (γ_slip − γ_stick))             (26)

independent of φ̇_m at a given t (the paper's remark after eq. 26).

Partial relief (the paper's dashed lines, Figures 13-15): a slip releases
only a fraction ρ of what the full model releases; the paper's "50 % of the
stored energy" is applied, as in its text, as "the screw is rotated only half
as much". So δ -> ρ·δ: ΔT and ΔF scale by ρ, Δt by ρ, f_ss by 1/ρ. (Were ρ
a fraction of the energy ½ k_e θ², the rotation would scale by 1 − √(1 − ρ)
instead; the paper does not do that, and neither do we.)

Note (not in the paper): the motor must also twist the extension further,
because the stick limit F · r · μ_stick rises with the preload; the exact
reload time of the model is δ / (γ_stick · φ̇_m). Eqs. 25-26 therefore put
f_ss a factor 1/γ_stick above the lumped model for the same δ. We keep the
paper's equations as the envelope; see :mod:`shared.model.characteristic_constants`.
"""

from __future__ import annotations

from shared.model.angles import Value, slip_angle_rad, twist_at_stick_rad

FULL_RELIEF = 1.0
PAPER_PARTIAL_RELIEF = 0.5


def torque_drop_min_nm(
    motor_angle_rad: Value, gamma_stick: float, gamma_slip: float, k_e_nm_per_rad: float
) -> Value:
    """ΔT_min = Δφ_b · k_e, Nm (eq. 21)."""
    return slip_angle_rad(motor_angle_rad, gamma_stick, gamma_slip) * k_e_nm_per_rad


def torque_drop_max_nm(motor_angle_rad: Value, gamma_stick: float, k_e_nm_per_rad: float) -> Value:
    """ΔT_max = φ_0,stick · k_e, Nm: the whole torque released (eq. 22)."""
    return twist_at_stick_rad(motor_angle_rad, gamma_stick) * k_e_nm_per_rad


def force_step_min_n(
    motor_angle_rad: Value, gamma_stick: float, gamma_slip: float, k_s_n_per_rad: float
) -> Value:
    """ΔF_min = Δφ_b · k_s, N (eq. 23)."""
    return slip_angle_rad(motor_angle_rad, gamma_stick, gamma_slip) * k_s_n_per_rad


def force_step_max_n(motor_angle_rad: Value, gamma_stick: float, k_s_n_per_rad: float) -> Value:
    """ΔF_max = φ_0,stick · k_s, N (eq. 24)."""
    return twist_at_stick_rad(motor_angle_rad, gamma_stick) * k_s_n_per_rad


def stick_slip_frequency_min_hz(time_s: Value, gamma_stick: float) -> Value:
    """f_ss,min = 1 / (t · (1 − γ_stick)), Hz (eq. 25); t > 0 is model time."""
    return 1.0 / (time_s * (1.0 - gamma_stick))


def stick_slip_frequency_max_hz(time_s: Value, gamma_stick: float, gamma_slip: float) -> Value:
    """f_ss,max = 1 / (t · (γ_slip − γ_stick)), Hz (eq. 26); t > 0 is model time."""
    return 1.0 / (time_s * (gamma_slip - gamma_stick))
