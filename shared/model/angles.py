"""Screw angles during stick and slip (paper Section 3.1, eqs. 11-20).

Angles in radians, φ_m = φ̇_m · t measured from the untwisted, unloaded
joint (t = 0: F = 0, T = 0); stiffnesses per radian (see
:mod:`shared.model.stiffness`). Every function takes floats or numpy arrays.

Derivation of γ (eqs. 11-17). In either friction state the extension torque
balances the friction torque of the lumped contact:

    (φ_m − φ_b) · k_e = F · r · μ_i                                  (11)
    φ_m · k_e = φ_b · k_e + F · r · μ_i                              (12, 13)
    F = k_s · φ_b                                                    (8)
    φ_m · k_e = φ_b · (k_e + k_s · r · μ_i)                          (14)
    φ_b = φ_m · k_e / (k_e + k_s · r · μ_i) = φ_m · γ_i              (15)

With μ_i = μ_stick the screw is at the angle where sticking breaks, the
lowest it can be at motor angle φ_m (eq. 16); with μ_i = μ_slip where a slip
comes to rest (eq. 17). μ_stick ≥ μ_slip gives γ_stick ≤ γ_slip < 1.
"""

from __future__ import annotations

from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

#: a float or a numpy array of floats; results have the broadcast shape
Value = TypeVar("Value", float, NDArray[np.float64])


def angle_ratio(k_e_nm_per_rad: Value, k_s_n_per_rad: float, r_m: float, mu: float) -> Value:
    """γ_i = k_e / (k_e + k_s · r · μ_i), dimensionless (eq. 15)."""
    return k_e_nm_per_rad / (k_e_nm_per_rad + k_s_n_per_rad * r_m * mu)


def bearing_angle_min_rad(motor_angle_rad: Value, gamma_stick: float) -> Value:
    """φ_b,min = φ_m · γ_stick: the screw angle at which sticking breaks (eq. 16)."""
    return motor_angle_rad * gamma_stick


def bearing_angle_max_rad(motor_angle_rad: Value, gamma_slip: float) -> Value:
    """φ_b,max = φ_m · γ_slip: the screw angle at which a slip comes to rest (eq. 17)."""
    return motor_angle_rad * gamma_slip


def slip_angle_rad(motor_angle_rad: Value, gamma_stick: float, gamma_slip: float) -> Value:
    """Δφ_b = φ_b,max − φ_b,min = φ_m · (γ_slip − γ_stick), the smallest slip (eq. 18)."""
    return motor_angle_rad * (gamma_slip - gamma_stick)


def twist_at_stick_rad(motor_angle_rad: Value, gamma_stick: float) -> Value:
    """φ_0,stick = φ_m − φ_b,min = φ_m · (1 − γ_stick), twist when sticking breaks (eq. 19).

    Also the largest slip: the screw cannot overtake the motor, where the
    extension is untwisted and T = 0 (Section 5.2).
    """
    return motor_angle_rad * (1.0 - gamma_stick)


def twist_at_slip_rad(motor_angle_rad: Value, gamma_slip: float) -> Value:
    """φ_0,slip = φ_m − φ_b,max = φ_m · (1 − γ_slip), twist left after a slip (eq. 20)."""
    return motor_angle_rad * (1.0 - gamma_slip)
