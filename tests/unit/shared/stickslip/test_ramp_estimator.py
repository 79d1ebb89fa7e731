"""The steady-ramp projection of the target rule (core/ramp_estimator.py)."""

from __future__ import annotations

import math

import pytest

from shared.stickslip import SPAN, RampEstimator


def test_steady_ramp_is_projected_over_the_lead() -> None:
    ramp = RampEstimator()
    for k in range(40):
        ramp.add(1000.0 + 50.0 * k)
    # newest value 1000 + 50·39; 1.5 samples of lead ahead of it
    assert ramp.projected(1.5) == pytest.approx(1000.0 + 50.0 * 40.5)


def test_staircase_and_flat_signals_are_not_ramps() -> None:
    stairs = RampEstimator()
    for k in range(60):
        stairs.add(1000.0 * (k // 20))  # a jump every 20 samples
        if k % 20 in (1, 2, 3):  # a jump within the last blocks
            assert math.isnan(stairs.projected(1.5))
    flat = RampEstimator()
    for _ in range(40):
        flat.add(5.0)
    assert math.isnan(flat.projected(1.5))


def test_nan_restarts_the_estimate() -> None:
    ramp = RampEstimator()
    for k in range(30):
        ramp.add(float(k))
    ramp.add(math.nan)
    for k in range(SPAN):
        ramp.add(float(k))
        assert math.isnan(ramp.projected(1.0))
