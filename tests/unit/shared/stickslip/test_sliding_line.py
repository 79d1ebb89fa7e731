"""The line through the newest samples: the least-squares fit of its window, O(1) per sample."""

from __future__ import annotations

import numpy as np
import pytest

from shared.stickslip.sliding_line import SlidingLine


def test_each_window_gives_numpys_least_squares_line() -> None:
    rng = np.random.default_rng(3)
    values = np.cumsum(rng.normal(0.4, 1.0, 500))
    line = SlidingLine(24)
    for n, value in enumerate(values, start=1):
        line.add(float(value))
        window = values[max(0, n - 24) : n]
        if len(window) < 2:
            assert np.isnan(line.slope) and np.isnan(line.end)
            continue
        slope, intercept = np.polyfit(np.arange(len(window)), window, 1)
        assert line.slope == pytest.approx(slope, rel=1e-9, abs=1e-9)
        assert line.end == pytest.approx(slope * (len(window) - 1) + intercept, rel=1e-9)
    assert len(line) == 24


def test_a_noisy_ramp_is_found_closer_than_its_newest_sample() -> None:
    rng = np.random.default_rng(5)
    errors_line, errors_sample = [], []
    for _ in range(200):
        ramp = 0.01 * np.arange(24) + rng.normal(0.0, 1.0, 24)
        line = SlidingLine(24)
        for value in ramp:
            line.add(float(value))
        errors_line.append(line.end - 0.23)
        errors_sample.append(ramp[-1] - 0.23)
    # the end of a line through 24 samples: 2σ/√24 ≈ 0.41 σ, against σ for one sample
    assert np.std(errors_line) < 0.55
    assert np.std(errors_sample) > 0.8


def test_cleared_it_starts_again_and_refuses_a_window_of_one() -> None:
    line = SlidingLine(4)
    for value in (1.0, 2.0, 3.0):
        line.add(value)
    line.clear()
    line.add(10.0)
    line.add(10.5)
    assert line.slope == pytest.approx(0.5) and line.end == pytest.approx(10.5)
    with pytest.raises(ValueError, match="at least 2 samples"):
        SlidingLine(1)
