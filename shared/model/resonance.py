"""First torsional natural frequency of the extension (paper Section 4, eq. 40).

    f_n = 1 / (2π) · √(G / (l_e² · ρ)) = c_t / (2π · l_e),  c_t = √(G / ρ)   (40)

c_t is the speed of torsional waves in the rod (≈ 3.2 km/s for steel). The
paper's formula is used as printed; note that the textbook first modes of a
uniform rod are c_t / (2 l_e) (free-free, fixed-fixed) and c_t / (4 l_e)
(fixed-free), i.e. π or π/2 times eq. 40. Both readings keep a 500 mm steel
extension above 1 kHz (eq. 40: 1.02 kHz), far above the stick-slip band, the
paper's conclusion. The diameter drops out: stiffness and inertia both grow
with J_p.
"""

from __future__ import annotations

import math

from shared.model.angles import Value


def torsional_wave_speed_m_s(shear_modulus_pa: float, density_kg_m3: float) -> float:
    """c_t = √(G / ρ), m/s."""
    return math.sqrt(shear_modulus_pa / density_kg_m3)


def extension_natural_frequency_hz(
    shear_modulus_pa: float, density_kg_m3: float, length_m: Value
) -> Value:
    """f_n = √(G / (l_e² ρ)) / 2π, Hz (eq. 40)."""
    return torsional_wave_speed_m_s(shear_modulus_pa, density_kg_m3) / (2.0 * math.pi * length_m)
