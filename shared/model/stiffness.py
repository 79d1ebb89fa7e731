"""Stiffnesses and friction radius of a joint (paper Section 3, eqs. 2, 3, 8).

Convention, stated once for all of boltwatch: every angle is in **radians**
and every stiffness is **per radian**. The paper's eq. 8 takes φ in
revolutions (Δl_s = φ_th · P, eq. 4, with P the advance per revolution), yet
its stiffness interval k_s = [30, 180] kN (Section 3.4) is per radian. With φ
in radians the advance is φ · P / 2π, hence

    k_s = (P / 2π) · E · A / l_s,   A = π d² / 4           (eq. 8, per radian)

so that F = k_s · φ_b with φ_b in radians. For the Section 5.2 joint this
gives k_s ≈ 78 kN/rad, inside the paper's interval; the per-revolution value
(≈ 492 kN/rev) would not be.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from shared.config import JointConfig

MM = 1e-3
GPA = 1e9


def extension_stiffness_nm_per_rad(
    shear_modulus_pa: float, diameter_m: float, length_m: float
) -> float:
    """k_e = G · J_p / l_e with J_p = π d_e⁴ / 32 (eq. 2), Nm/rad."""
    polar_moment_m4 = math.pi / 32.0 * diameter_m**4
    return shear_modulus_pa * polar_moment_m4 / length_m


def friction_radius_m(inner_diameter_m: float, outer_diameter_m: float) -> float:
    """Surrogate bearing friction radius (eq. 3), m.

    r = 2/3 · r_b,min · (γ² + γ + 1) / (1 + γ) with γ = r_b,max / r_b,min,
    which is the classic (2/3)(R³ - r³)/(R² - r²) of a uniformly loaded annulus.
    """
    r_min = inner_diameter_m / 2.0
    gamma = (outer_diameter_m / 2.0) / r_min
    return 2.0 / 3.0 * r_min * (gamma**2 + gamma + 1.0) / (1.0 + gamma)


def screw_stiffness_n_per_rad(
    pitch_m: float, youngs_modulus_pa: float, shaft_length_m: float, shaft_diameter_m: float
) -> float:
    """k_s of eq. 8 per radian of screw rotation, N/rad (see the module docstring)."""
    area_m2 = math.pi * shaft_diameter_m**2 / 4.0
    return pitch_m / (2.0 * math.pi) * youngs_modulus_pa * area_m2 / shaft_length_m


@dataclass(frozen=True, slots=True)
class JointConstants:
    """The SI constants of the lumped model (Figure 1) for one joint."""

    k_e_nm_per_rad: float  # extension, eq. 2
    k_s_n_per_rad: float  # screw, eq. 8 (per radian)
    r_m: float  # bearing friction radius, eq. 3
    mu_stick: float
    mu_slip: float

    @classmethod
    def of(cls, joint: JointConfig) -> JointConstants:
        """Derive the constants of a configured joint."""
        return cls(
            k_e_nm_per_rad=extension_stiffness_nm_per_rad(
                joint.material.shear_modulus_gpa * GPA,
                joint.extension.diameter_mm * MM,
                joint.extension.length_mm * MM,
            ),
            k_s_n_per_rad=screw_stiffness_n_per_rad(
                joint.screw.pitch_mm * MM,
                joint.material.youngs_modulus_gpa * GPA,
                joint.screw.shaft_length_mm * MM,
                joint.screw.shaft_diameter_mm * MM,
            ),
            r_m=friction_radius_m(
                joint.screw.bearing_inner_diameter_mm * MM,
                joint.screw.bearing_outer_diameter_mm * MM,
            ),
            mu_stick=joint.friction.mu_stick,
            mu_slip=joint.friction.mu_slip,
        )
