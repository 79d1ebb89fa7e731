"""Time to target and the model's time origin (paper Section 3.2, eqs. 27-29).

Time origin. The model's motor angle is φ_m = φ̇_m · t from the untwisted,
unloaded joint (t = 0: F = 0, T = 0). A real run starts later (the paper's
measured data starts at F = 10 kN and is shifted by 0.15 s to compare, Section
5.2); bounds must be evaluated at model time, so this module maps a preload or
a torque to it.

Eqs. 27-29. The motor angle splits into the twist of the extension and the
angle of the screw, φ_m = T / k_e + F / k_s, so at constant speed

    t_total = t_e + t_screw                                          (27)
    t_e     = T_target / (φ̇_m · k_e)                                 (28)
    t_screw = F_target / φ̇_m · l_s / (P · E) · 8 / d²                (29)

Eq. 29 as printed is already per radian: with k_s = P/(2π) · E · π d²/4 / l_s
= P · E · d² / (8 · l_s) (eq. 8 per radian, :mod:`shared.model.stiffness`),
F / (φ̇_m · k_s) = F / φ̇_m · 8 · l_s / (P · E · d²), the "8" being 2π · 4/π.
So t_screw = F / (φ̇_m · k_s) with φ̇_m in rad/s: the same convention as
everywhere else (read with φ̇_m in rev/s it would be 2π too large).

Time at a preload. Sticking breaks on the line φ_b = γ_stick · φ_m (eq. 16),
so each force plateau F is left at φ_m = F / (k_s · γ_stick). That is eq. 27
with the torque that belongs to F, T = F · r · μ_stick (eq. 9):

    t(F) = F / (φ̇_m k_s) + F r μ / (φ̇_m k_e)
         = F (k_e + k_s r μ) / (φ̇_m k_s k_e) = F / (φ̇_m · k_s · γ(μ))
    t(T) = T / (φ̇_m · k_e · (1 − γ(μ)))     (from T = φ_0 · k_e, eq. 19)

With μ = μ_slip instead, the time at which a slip comes to rest at F (eq. 17;
the rig starts its runs there).
"""

from __future__ import annotations

from shared.model.angles import Value


def extension_twist_time_s(
    target_torque_nm: Value, motor_speed_rad_s: float, k_e_nm_per_rad: float
) -> Value:
    """t_e = T_target / (φ̇_m · k_e), s (eq. 28)."""
    return target_torque_nm / (motor_speed_rad_s * k_e_nm_per_rad)


def screw_tension_time_s(
    target_force_n: Value, motor_speed_rad_s: float, k_s_n_per_rad: float
) -> Value:
    """t_screw = F_target / (φ̇_m · k_s), s (eq. 29, per radian; see the module docstring)."""
    return target_force_n / (motor_speed_rad_s * k_s_n_per_rad)


def total_time_s(
    target_torque_nm: Value,
    target_force_n: Value,
    motor_speed_rad_s: float,
    k_e_nm_per_rad: float,
    k_s_n_per_rad: float,
) -> Value:
    """t_total = t_e + t_screw, s (eq. 27), for independently given T and F targets."""
    return extension_twist_time_s(
        target_torque_nm, motor_speed_rad_s, k_e_nm_per_rad
    ) + screw_tension_time_s(target_force_n, motor_speed_rad_s, k_s_n_per_rad)


def time_at_force_s(
    force_n: Value, motor_speed_rad_s: float, k_s_n_per_rad: float, gamma: float
) -> Value:
    """Model time t at which preload F sits on the line φ_b = γ · φ_m, s (eqs. 15, 27)."""
    return force_n / (motor_speed_rad_s * k_s_n_per_rad * gamma)


def time_at_torque_s(
    torque_nm: Value, motor_speed_rad_s: float, k_e_nm_per_rad: float, gamma: float
) -> Value:
    """Model time t at which the extension torque T = φ_m (1 − γ) k_e, s (eqs. 15, 19, 27)."""
    return torque_nm / (motor_speed_rad_s * k_e_nm_per_rad * (1.0 - gamma))
