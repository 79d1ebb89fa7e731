"""Eqs. 15-39 against values computed by hand for round constants.

k_e = 1000 Nm/rad, k_s = 100 kN/rad, r = 10 mm, μ_stick = 0.5, μ_slip = 0.25:
k_s r μ = 500 and 250 Nm/rad, so γ_stick = 1000/1500 = 2/3, γ_slip = 1000/1250
= 0.8. At φ̇_m = 0.5 rad/s and t = 2 s: φ_m = 1 rad, Δφ_b = 2/15 rad,
φ_0,stick = 1/3 rad.
"""

from __future__ import annotations

import numpy as np
import pytest

from shared.model import (
    JointConstants,
    JointModel,
    expected_constant_bands,
    k1_of,
    k2_of,
    k3_of,
    screw_tension_time_s,
    stick_line_k2,
    total_time_s,
)

ROUND = JointConstants(
    k_e_nm_per_rad=1000.0, k_s_n_per_rad=100_000.0, r_m=0.01, mu_stick=0.5, mu_slip=0.25
)
SPEED_RAD_S = 0.5
T_S = 2.0


@pytest.fixture
def model() -> JointModel:
    return JointModel(ROUND, SPEED_RAD_S)


def test_gammas(model: JointModel) -> None:
    assert model.gamma_stick == pytest.approx(2 / 3)
    assert model.gamma_slip == pytest.approx(0.8)


def test_angles(model: JointModel) -> None:
    assert model.motor_angle_rad(T_S) == pytest.approx(1.0)
    assert model.bearing_angle_min_rad(T_S) == pytest.approx(2 / 3)
    assert model.bearing_angle_max_rad(T_S) == pytest.approx(0.8)
    assert model.slip_angle_rad(T_S) == pytest.approx(2 / 15)
    assert model.twist_at_stick_rad(T_S) == pytest.approx(1 / 3)


def test_torque_and_force_bounds(model: JointModel) -> None:
    assert model.torque_drop_min_nm(T_S) == pytest.approx(1000 * 2 / 15)
    assert model.torque_drop_max_nm(T_S) == pytest.approx(1000 / 3)
    assert model.force_step_min_n(T_S) == pytest.approx(100_000 * 2 / 15)
    assert model.force_step_max_n(T_S) == pytest.approx(100_000 / 3)
    # Figure 10 envelopes: sticking breaks at T = F r μ_stick (eq. 9)
    assert model.peak_torque_nm(T_S) == pytest.approx(
        model.force_at_stick_n(T_S) * ROUND.r_m * ROUND.mu_stick
    )
    assert model.slip_torque_nm(T_S) == pytest.approx(
        model.force_at_slip_n(T_S) * ROUND.r_m * ROUND.mu_slip
    )


def test_frequency_bounds(model: JointModel) -> None:
    assert model.stick_slip_frequency_min_hz(T_S) == pytest.approx(1.5)  # 1/(2 · 1/3)
    assert model.stick_slip_frequency_max_hz(T_S) == pytest.approx(3.75)  # 1/(2 · 2/15)


def test_bounds_accept_arrays(model: JointModel) -> None:
    t_s = np.array([1.0, 2.0, 4.0])
    np.testing.assert_allclose(model.stick_slip_frequency_max_hz(t_s), [7.5, 3.75, 1.875])
    np.testing.assert_allclose(model.force_step_max_n(t_s), 100_000 / 3 * t_s / 2)


def test_partial_relief_halves_slips_and_doubles_frequencies(model: JointModel) -> None:
    half = model.with_relief(0.5)
    assert half.force_step_max_n(T_S) == pytest.approx(model.force_step_max_n(T_S) / 2)
    assert half.torque_drop_min_nm(T_S) == pytest.approx(model.torque_drop_min_nm(T_S) / 2)
    assert half.stick_slip_frequency_min_hz(T_S) == pytest.approx(3.0)
    # the trace envelopes do not depend on how much a slip releases
    assert half.peak_torque_nm(T_S) == pytest.approx(model.peak_torque_nm(T_S))


def test_constant_bands_by_hand() -> None:
    bands = expected_constant_bands(ROUND, SPEED_RAD_S)
    assert bands.k1_min == pytest.approx(3.0)  # 1/(1 − 2/3)
    assert bands.k1_max == pytest.approx(7.5)  # 1/(0.8 − 2/3)
    assert bands.k2_min == pytest.approx(10_000.0)  # 1e5 · 0.25 · (2/15)/(1/3)
    assert bands.k2_max == pytest.approx(62_500.0)  # 1e5 · 0.25 · (1/3)/(2/15)
    assert bands.k3_min == pytest.approx(1000 * 0.25 * 2 / 15)
    assert bands.k3_max == pytest.approx(1000 * 0.25 / 3)
    assert bands.k2_min < stick_line_k2(ROUND, SPEED_RAD_S) < bands.k2_max


@pytest.mark.parametrize("t_s", [0.3, 2.0, 11.0])
def test_bands_are_the_eq_31_to_33_of_the_bounds_at_any_time(model: JointModel, t_s: float) -> None:
    bands = model.constant_bands()
    f_min, f_max = model.stick_slip_frequency_min_hz(t_s), model.stick_slip_frequency_max_hz(t_s)
    assert k1_of(f_min, t_s) == pytest.approx(bands.k1_min)
    assert k1_of(f_max, t_s) == pytest.approx(bands.k1_max)
    assert k2_of(model.force_step_min_n(t_s), 1 / f_min, SPEED_RAD_S) == pytest.approx(bands.k2_min)
    assert k2_of(model.force_step_max_n(t_s), 1 / f_max, SPEED_RAD_S) == pytest.approx(bands.k2_max)
    assert k3_of(model.torque_drop_min_nm(t_s), t_s, SPEED_RAD_S) == pytest.approx(bands.k3_min)
    assert k3_of(model.torque_drop_max_nm(t_s), t_s, SPEED_RAD_S) == pytest.approx(bands.k3_max)


def test_relief_scales_k1_and_k3_but_not_k2() -> None:
    full = expected_constant_bands(ROUND, SPEED_RAD_S)
    half = expected_constant_bands(ROUND, SPEED_RAD_S, relief_fraction=0.5)
    assert half.k1_max == pytest.approx(2 * full.k1_max)
    assert half.k3_min == pytest.approx(full.k3_min / 2)
    assert (half.k2_min, half.k2_max) == pytest.approx((full.k2_min, full.k2_max))


def test_time_maps_to_the_target(model: JointModel) -> None:
    force_n = 100_000 * 2 / 3  # on the stick line at φ_m = 1 rad
    assert model.time_at_force_s(force_n) == pytest.approx(T_S)
    assert model.time_at_force_s(80_000.0, at_slip=True) == pytest.approx(T_S)
    assert model.time_at_torque_s(1000 / 3) == pytest.approx(T_S)
    # eq. 27 with the torque that belongs to F (eq. 9) is the same time
    torque_nm = force_n * ROUND.r_m * ROUND.mu_stick
    assert model.total_time_s(torque_nm, force_n) == pytest.approx(T_S)


def test_eq_29_as_printed_is_per_radian() -> None:
    # t_screw = F / φ̇_m · l_s / (P E) · 8 / d² for the Section 5.2 screw
    f_n, l_s, p, e, d = 56_000.0, 0.085, 1.5e-3, 210e9, 13e-3
    printed_s = f_n / SPEED_RAD_S * l_s / (p * e) * 8 / d**2
    k_s = p * e * d**2 / (8 * l_s)  # eq. 8 per radian
    assert screw_tension_time_s(f_n, SPEED_RAD_S, k_s) == pytest.approx(printed_s)
    assert total_time_s(0.0, f_n, SPEED_RAD_S, 1.0, k_s) == pytest.approx(printed_s)


def test_bad_arguments_are_refused() -> None:
    with pytest.raises(ValueError, match="motor_speed_rad_s"):
        JointModel(ROUND, 0.0)
    with pytest.raises(ValueError, match="relief_fraction"):
        expected_constant_bands(ROUND, 1.0, relief_fraction=0.0)
