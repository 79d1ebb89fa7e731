"""The paper's own numbers, reproduced from its stated parameters."""

from __future__ import annotations

import itertools
import math

import pytest

from shared.config import JointConfig
from shared.model import (
    JointConstants,
    apparent_friction_coefficient,
    extension_natural_frequency_hz,
    extension_stiffness_nm_per_rad,
    friction_radius_m,
    total_friction_coefficient,
)

# Section 5.2: T = 200 Nm, F = 56 kN, d2 = 12.6 mm, P = 1.5 mm, d_i = 14, d_o = 29 mm
T_TARGET_NM, F_TARGET_N = 200.0, 56_000.0
R_5_2_M = friction_radius_m(14e-3, 29e-3)


def test_friction_radius_of_section_5_2() -> None:
    # eq. 3 = (2/3)(R³ − r³)/(R² − r²) with R = 14.5, r = 7 mm
    expected_m = 2 / 3 * (14.5**3 - 7.0**3) / (14.5**2 - 7.0**2) * 1e-3
    radius_m = R_5_2_M
    assert radius_m == pytest.approx(expected_m, rel=1e-12)
    assert radius_m == pytest.approx(11.186e-3, abs=1e-6)


def test_mu_total_eq_41_is_0_18() -> None:
    mu = total_friction_coefficient(T_TARGET_NM, F_TARGET_N, 1.5e-3, 12.6e-3, R_5_2_M)
    assert round(mu, 2) == 0.18


def test_mu_apparent_eq_42_is_0_32() -> None:
    assert round(apparent_friction_coefficient(T_TARGET_NM, F_TARGET_N, R_5_2_M), 2) == 0.32


def test_extension_natural_frequency_above_1_khz_at_500_mm() -> None:
    f_n = extension_natural_frequency_hz(81e9, 7900.0, 0.5)
    assert 1000.0 < f_n < 1050.0  # eq. 40: √(G/ρ) / (2π · 0.5 m) = 1019 Hz


def test_section_3_4_stiffnesses_inside_the_paper_intervals(joint_3_4: JointConfig) -> None:
    constants = JointConstants.of(joint_3_4)
    assert 200.0 <= constants.k_e_nm_per_rad <= 2000.0  # k_e = [200, 2000] Nm(/rad)
    assert constants.k_e_nm_per_rad == pytest.approx(397.6, abs=0.1)
    assert 30e3 <= constants.k_s_n_per_rad <= 180e3  # k_s = [30, 180] kN(/rad)
    assert constants.k_s_n_per_rad == pytest.approx(90.79e3, rel=1e-3)


def test_k_e_interval_against_the_typical_extension_corners() -> None:
    """The paper's k_e = [200, 2000] is NOT the corner span of l_e 50-500 x d_e 8-15 mm.

    The corners give 65 .. 8050 Nm/rad (d_e⁴ spans 12x, l_e 10x); the paper's
    interval lies inside that span. The diagonal corners (short and thin, long
    and thick) do fall in it. Recorded so the discrepancy is not rediscovered.
    """
    corners = {
        (l_mm, d_mm): extension_stiffness_nm_per_rad(81e9, d_mm * 1e-3, l_mm * 1e-3)
        for l_mm, d_mm in itertools.product((50.0, 500.0), (8.0, 15.0))
    }
    assert min(corners.values()) == pytest.approx(65.1, abs=0.1)
    assert max(corners.values()) == pytest.approx(8052.0, rel=1e-3)
    assert 200.0 <= corners[(50.0, 8.0)] <= 2000.0
    assert 200.0 <= corners[(500.0, 15.0)] <= 2000.0


def test_k_s_of_section_5_2_is_per_radian(constants_5_2: JointConstants) -> None:
    # eq. 8 per radian: P/2π · E · π d²/4 / l_s = 1.5e-3 · 210e9 · 13e-3² / (8 · 0.085)
    assert constants_5_2.k_s_n_per_rad == pytest.approx(
        1.5e-3 * 210e9 * 13e-3**2 / (8 * 0.085), rel=1e-12
    )
    assert constants_5_2.k_e_nm_per_rad == pytest.approx(
        math.pi / 32 * 81e9 * 0.01**4 / 0.11, rel=1e-12
    )
