"""Joint files for drawn joints: the geometry whose constants are the drawn ones.

The benchmarks draw joints as the lumped model's constants (k_e, k_s, r,
μ_stick, μ_slip); a station names its joints as files of geometry and
material (``shared/config/joint.py``). The geometry is solved from the
constants with the steel of the paper's Section 5.2 (G 81 GPa, E 210 GPa):

- extension of 10 mm diameter, length l_e = G π d⁴ / (32 k_e)       (eq. 2)
- screw M14x1.5, shaft of 13 mm, clamped length l_s = P/2π · E A / k_s  (eq. 8)
- bearing of 14 mm inner diameter, the outer one solved for r        (eq. 3)

and :func:`joint_toml` checks that the file gives back the constants.
"""

from __future__ import annotations

import math
import tomllib

from shared.config import JointConfig
from shared.model import JointConstants, friction_radius_m

SHEAR_MODULUS_GPA = 81.0
YOUNGS_MODULUS_GPA = 210.0
EXTENSION_DIAMETER_MM = 10.0
PITCH_MM = 1.5
SHAFT_DIAMETER_MM = 13.0
BEARING_INNER_MM = 14.0


def joint_toml(constants: JointConstants, name: str = "drawn joint") -> str:
    """The joint file of ``constants``; ValueError if it would not give them back."""
    d_e = EXTENSION_DIAMETER_MM * 1e-3
    l_e = SHEAR_MODULUS_GPA * 1e9 * math.pi * d_e**4 / (32.0 * constants.k_e_nm_per_rad)
    area = math.pi * (SHAFT_DIAMETER_MM * 1e-3) ** 2 / 4.0
    l_s = PITCH_MM * 1e-3 / (2.0 * math.pi) * YOUNGS_MODULUS_GPA * 1e9 * area
    l_s /= constants.k_s_n_per_rad
    outer_mm = _outer_diameter_mm(constants.r_m)
    text = f"""name = "{name}"

[material]
shear_modulus_gpa = {SHEAR_MODULUS_GPA}
youngs_modulus_gpa = {YOUNGS_MODULUS_GPA}
density_kg_m3 = 7900.0

[screw]
pitch_mm = {PITCH_MM}
shaft_diameter_mm = {SHAFT_DIAMETER_MM}
shaft_length_mm = {l_s * 1e3!r}
pitch_diameter_mm = 12.6
bearing_outer_diameter_mm = {outer_mm!r}
bearing_inner_diameter_mm = {BEARING_INNER_MM}

[extension]
length_mm = {l_e * 1e3!r}
diameter_mm = {EXTENSION_DIAMETER_MM}

[friction]
mu_stick = {constants.mu_stick!r}
mu_slip = {constants.mu_slip!r}
"""
    back = JointConstants.of(JointConfig.model_validate(tomllib.loads(text)))
    for field in ("k_e_nm_per_rad", "k_s_n_per_rad", "r_m", "mu_stick", "mu_slip"):
        if not math.isclose(getattr(back, field), getattr(constants, field), rel_tol=1e-9):
            raise ValueError(f"{field}: the joint file gives {getattr(back, field)}")
    return text


def _outer_diameter_mm(r_m: float) -> float:
    """The bearing's outer diameter whose friction radius with the inner one is ``r_m``."""
    inner = BEARING_INNER_MM * 1e-3
    low, high = inner * (1.0 + 1e-9), inner * 20.0
    if not friction_radius_m(inner, low) < r_m < friction_radius_m(inner, high):
        raise ValueError(
            f"friction radius {r_m} m is out of reach with a {BEARING_INNER_MM} mm bore"
        )
    for _ in range(200):
        middle = 0.5 * (low + high)
        if friction_radius_m(inner, middle) < r_m:
            low = middle
        else:
            high = middle
    return 0.5 * (low + high) * 1e3
