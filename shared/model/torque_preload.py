"""Torque and preload, and the friction seen in them (paper eqs. 30, 41, 42).

The thread is a wedge: one turn advances P, so the preload F alone needs
F · P / 2π (the "pitch torque"). Thread friction acts at d_2 / 2 on a
60° flank, i.e. at an effective radius (d_2 / 2) / cos 30° = d_2 / √3;
bearing friction at D_b / 2. Kellermann and Klein / VDI 2230 (paper eq. 30):

    T = F · (P / 2π + d_2 / √3 · μ_th + D_b / 2 · μ_b)              (30)

We take D_b / 2 = r, the surrogate friction radius of eq. 3, as eq. 41 does.
With one coefficient for both contacts, μ_th = μ_b = μ_total, eq. 30 solved
for it is

    μ_total = (T / F − P / 2π) / (d_2 / √3 + r)                      (41)

and the paper's single-contact model (eq. 9, the screw torque only at the
bearing, no pitch torque) gives the apparent coefficient

    μ* = T / (F · r)                                                 (42)

Lengths in m, torques in Nm, forces in N.
"""

from __future__ import annotations

import math

from shared.model.angles import Value

SQRT3 = math.sqrt(3.0)


def pitch_lever_m(pitch_m: float) -> float:
    """P / 2π: the torque per newton of preload that a frictionless thread needs, m."""
    return pitch_m / (2.0 * math.pi)


def torque_lever_m(
    pitch_m: float,
    pitch_diameter_m: float,
    friction_radius_m: float,
    mu_thread: float,
    mu_bearing: float,
) -> float:
    """P/2π + d_2/√3 · μ_th + r · μ_b, m: torque per newton of preload (eq. 30)."""
    return (
        pitch_lever_m(pitch_m)
        + pitch_diameter_m / SQRT3 * mu_thread
        + friction_radius_m * mu_bearing
    )


def torque_for_force_nm(
    force_n: Value,
    pitch_m: float,
    pitch_diameter_m: float,
    friction_radius_m: float,
    mu_thread: float,
    mu_bearing: float,
) -> Value:
    """T = F · (P/2π + d_2/√3 · μ_th + r · μ_b), Nm (eq. 30 with D_b/2 = r)."""
    lever_m = torque_lever_m(pitch_m, pitch_diameter_m, friction_radius_m, mu_thread, mu_bearing)
    return force_n * lever_m


def force_for_torque_n(
    torque_nm: Value,
    pitch_m: float,
    pitch_diameter_m: float,
    friction_radius_m: float,
    mu_thread: float,
    mu_bearing: float,
) -> Value:
    """F = T / (P/2π + d_2/√3 · μ_th + r · μ_b), N (eq. 30 solved for F)."""
    lever_m = torque_lever_m(pitch_m, pitch_diameter_m, friction_radius_m, mu_thread, mu_bearing)
    return torque_nm / lever_m


def total_friction_coefficient(
    torque_nm: Value,
    force_n: Value,
    pitch_m: float,
    pitch_diameter_m: float,
    friction_radius_m: float,
) -> Value:
    """μ_total = (T/F − P/2π) / (d_2/√3 + r), dimensionless (eq. 41)."""
    return (torque_nm / force_n - pitch_lever_m(pitch_m)) / (
        pitch_diameter_m / SQRT3 + friction_radius_m
    )


def apparent_friction_coefficient(
    torque_nm: Value, force_n: Value, friction_radius_m: float
) -> Value:
    """μ* = T / (F · r), dimensionless (eq. 42)."""
    return torque_nm / (force_n * friction_radius_m)
