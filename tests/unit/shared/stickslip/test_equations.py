"""Each equation of the core against hand-computed values."""

from __future__ import annotations

import math

import pytest

from shared.contract import Prediction
from shared.stickslip import (
    MAX_PASSED,
    MIN_PASSED,
    NO_FLIP,
    ForceHistory,
    InclinationWindow,
    PredictionScores,
    compute_figures,
    event_intensity,
    fit_line,
    fit_parabola,
    predict_periods,
    predict_plateaus,
    torque_mean_nm,
)


def test_slope_sum_is_eq_46_over_the_window_pairs() -> None:
    window = InclinationWindow(3)
    # pairs: (0,0)->(1ms,2): 2000; (1ms,2)->(3ms,1): -500; then the first pair leaves.
    window.push(0, 0.000, 0.0, 0.0, 1e-3)
    window.push(1, 0.001, 2.0, 0.0, 1e-3)
    window.push(2, 0.003, 1.0, 0.0, 1e-3)
    assert window.slope_sum == pytest.approx(2000.0 - 500.0)
    window.push(3, 0.004, 4.0, 0.0, 1e-3)  # +3000; the 2000 pair leaves
    assert window.slope_sum == pytest.approx(-500.0 + 3000.0)


def test_repeated_timestamp_uses_half_the_nominal_period() -> None:
    window = InclinationWindow(3)
    window.push(0, 0.001, 1.0, 0.0, 1e-3)
    window.push(1, 0.001, 2.0, 0.0, 1e-3)  # Δt = 0 -> 0.5 ms
    assert window.slope_sum == pytest.approx(1.0 / 0.0005)


def test_sign_flips_mark_maximum_then_minimum_eqs_47_to_51() -> None:
    window = InclinationWindow(3)
    torques = [0.0, 1.0, 2.0, 3.0, 1.0, 0.5, 0.6, 2.0]
    flips = []
    for i, torque in enumerate(torques):
        flips.append(window.push(i, i * 1e-3, torque, 0.0, 1e-3))
        if flips[-1] == MAX_PASSED:  # window [2, 3, 1]: S = 1000 - 2000 < 0
            slot = window.argmax()
            assert (window.time_s[slot], window.torque_nm[slot]) == (0.003, 3.0)  # eqs. 48, 49
        if flips[-1] == MIN_PASSED:
            assert window.torque_nm[window.argmin()] == 0.5  # eqs. 50, 51
    assert flips[:4] == [NO_FLIP] * 4
    assert flips[4] == MAX_PASSED
    assert MIN_PASSED in flips[5:]


def test_running_sum_matches_a_fresh_sum_after_many_samples() -> None:
    window = InclinationWindow(5)
    for i in range(10_000):
        window.push(i, i * 1e-3, math.sin(i / 7.0) * 100.0, 0.0, 1e-3)
    fresh = sum(
        (window.torque_nm[b] - window.torque_nm[a]) / 1e-3
        for a, b in zip(
            window.slots_oldest_first()[:-1], window.slots_oldest_first()[1:], strict=True
        )
    )
    assert window.slope_sum == pytest.approx(fresh, rel=1e-9, abs=1e-6)


def test_event_figures_eqs_31_33_66_67() -> None:
    figures = compute_figures(
        index=2,
        time_since_start_s=0.5,
        peak_torque_nm=120.0,
        min_torque_nm=100.0,
        plateau_force_n=40_000.0,
        previous_time_s=0.48,
        previous_plateau_n=39_000.0,
        time_s=0.5,
        motor_speed_rad_s=0.5,
    )
    assert figures.torque_drop_nm == 20.0
    assert figures.force_step_n == 1000.0
    assert figures.period_s == pytest.approx(0.02)
    assert figures.f_ss_hz == pytest.approx(50.0)
    assert figures.k1 == pytest.approx(50.0 * 0.5)  # eq. 31
    assert figures.k2 == pytest.approx(1000.0 / 0.02 * 0.5)  # eq. 32
    assert figures.k3 == pytest.approx(20.0 / 0.5 * 0.5)  # eq. 33
    assert torque_mean_nm(120.0, 100.0) == 110.0  # eq. 66
    assert figures.intensity == pytest.approx(20.0 * 110.0 * 50.0)  # eq. 67
    assert event_intensity(2.0, 3.0, 4.0) == 24.0


def test_first_event_has_no_period_step_or_intensity() -> None:
    figures = compute_figures(
        index=1,
        time_since_start_s=0.1,
        peak_torque_nm=10.0,
        min_torque_nm=8.0,
        plateau_force_n=None,
        previous_time_s=None,
        previous_plateau_n=None,
        time_s=0.1,
        motor_speed_rad_s=None,
    )
    assert (figures.period_s, figures.f_ss_hz, figures.k1, figures.intensity) == (None,) * 4
    assert (figures.force_step_n, figures.k2, figures.k3) == (None, None, None)


def test_least_squares_line_and_parabola_eq_52() -> None:
    assert fit_line([1.0, 3.0, 5.0]) == pytest.approx((1.0, 2.0))
    assert fit_line([1.0, 2.0, 2.0, 3.0]) == pytest.approx((1.1, 0.6))  # hand: x̄=1.5, ȳ=2
    a, b, c = fit_parabola([1.0, 2.0, 5.0, 10.0])  # y = 1 + x²
    assert (a, b, c) == pytest.approx((1.0, 0.0, 1.0), abs=1e-9)


def test_period_prediction_eqs_53_to_56() -> None:
    # Δt grows by 1 ms per event: the next three are 14, 15, 16 ms.
    assert predict_periods([0.010, 0.011, 0.012, 0.013]) == pytest.approx([0.014, 0.015, 0.016])
    # An implausible extrapolation falls back on the last period.
    assert predict_periods([0.010, 0.030, 0.002])[0] == pytest.approx(0.002)


def test_plateau_methods_and_their_guard() -> None:
    plateaus = [10_000.0, 11_000.0, 12_100.0, 13_300.0, 14_600.0]  # steps 1000, 1100, 1200, 1300
    poly = predict_plateaus(plateaus, "poly2")
    assert poly == pytest.approx([16_000.0, 17_500.0, 19_100.0])
    linear = predict_plateaus(plateaus, "linear")
    assert linear is not None and linear[0] == pytest.approx(15_650.0)  # x̄=2, b=1150
    mean = predict_plateaus(plateaus, "mean_step")
    assert mean == pytest.approx([14_600.0 + 1200.0 * h for h in (1, 2, 3)])
    # A parabola bending down below the last plateau is replaced by the mean step.
    bent = [10_000.0, 12_000.0, 13_000.0, 13_500.0, 13_600.0]
    guarded = predict_plateaus(bent, "poly2")
    assert guarded is not None and guarded[0] > 13_600.0
    assert predict_plateaus([10_000.0], "poly2") is None


def test_prediction_errors_eqs_61_to_63() -> None:
    scores = PredictionScores()
    scores.remember(1, [Prediction(1, 0.110, 95.0, 20_200.0)])
    scores.score(2, 0.100, 0.020, 100.0, 20_000.0, 90.0, 1000.0)
    means = scores.summary()["1"]
    assert means["time"] == pytest.approx(0.010 / 0.020)  # eq. 61
    assert means["torque"] == pytest.approx(5.0 / 100.0)  # eq. 62
    assert means["force"] == pytest.approx(200.0 / 20_000.0)  # eq. 63
    immanent = scores.summary()["immanent"]
    assert immanent["torque"] == pytest.approx(10.0 / 100.0)
    assert immanent["force"] == pytest.approx(1000.0 / 20_000.0)


def test_force_history_means() -> None:
    history = ForceHistory()
    for value in [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]:
        history.add(value)
    assert history.mean(1, 3) == pytest.approx(3.0)
    assert history.plateau_before(-1, 5) == pytest.approx((4.0 + 5.0 + 6.0) / 3)  # 2nd half
    assert history.plateau_after(3) == pytest.approx(5.5)


def test_an_event_around_negative_torque_wears_the_tool_too() -> None:
    """Random frames gave a negative process intensity (-2e9) in the wear ledger."""
    assert event_intensity(2.0, -3.0, 4.0) == event_intensity(2.0, 3.0, 4.0) == 24.0
