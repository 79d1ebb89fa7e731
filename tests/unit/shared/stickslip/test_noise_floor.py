"""The slip detector's noise floor from the first samples of a run (core/extremum_tracker.py).

A slow stick ramp with white noise and no slip at all: whatever the detector
reports is a false event. Started from a single |d2|, the running median
could sit 10-25 times below the noise for hundreds of samples, and the ramp's
wiggles passed as slips there (seed 1, joint 80 of the accuracy
benchmark). Fixed seeds, so the counts are exact, not a flaky statistic.
"""

from __future__ import annotations

import math

import numpy as np

from shared.stickslip import (
    SEED_SAMPLES,
    EventFigures,
    ExtremumTracker,
    MotorMotion,
    PredictorCore,
    PredictorSettings,
)

NOISE_NM = 0.2  # the rig's torque noise
RAMP_NM_PER_SAMPLE = 0.05  # a slow stick ramp: k_e 334 Nm/rad at 0.15 rad/s, 1 kHz
SAMPLES = 2000
RUNS = 50
#: median |T_i - 2 T_(i-1) + T_(i-2)| of white noise: 0.674 · √6 σ
D2_MEDIAN_NM = 0.6745 * math.sqrt(6.0) * NOISE_NM


def noisy_ramp(seed: int) -> list[float]:
    rng = np.random.default_rng(seed)
    ramp = 20.0 + RAMP_NM_PER_SAMPLE * np.arange(SAMPLES)
    return [float(t) for t in ramp + rng.normal(0.0, NOISE_NM, SAMPLES)]


def event_samples(torques_nm: list[float]) -> list[int]:
    """Sample indices at which a torque-only core (no target) reports an event."""
    core = PredictorCore(PredictorSettings(has_force=False))
    found = []
    for i, torque_nm in enumerate(torques_nm):
        for output in core.update(i * 1e-3, torque_nm, math.nan, 0.01 * i):
            if isinstance(output, EventFigures):
                found.append(i)
    return found


def test_the_estimate_starts_near_the_noise_median() -> None:
    after = SEED_SAMPLES + 8
    ratios = []
    for seed in range(RUNS):
        tracker = ExtremumTracker(MotorMotion())
        for torque_nm in noisy_ramp(seed)[:after]:
            tracker.torque_noise.add(torque_nm)
        ratios.append(tracker.noise_d2_nm / D2_MEDIAN_NM)
    # one |d2| as the start gave 0.07 .. 2.5 here
    assert min(ratios) >= 0.5 and max(ratios) <= 2.0, (min(ratios), max(ratios))


def test_a_slow_noisy_ramp_has_no_more_false_events_at_its_start_than_later() -> None:
    early = late = 0
    for seed in range(RUNS):
        found = event_samples(noisy_ramp(seed))
        early += sum(i < 400 for i in found)
        late += sum(i >= SAMPLES - 400 for i in found)
    # one |d2| as the start: 124 in the first 400 samples against 7 in the last 400
    assert late < 20
    assert early <= 2 * late + 5, (early, late)


def test_no_event_on_a_clean_ramp_or_a_constant_from_the_first_sample() -> None:
    # |d2| = 0 throughout: the floor is then REL_FLOOR of the torque alone
    assert event_samples([20.0 + 0.05 * i for i in range(400)]) == []
    assert event_samples([50.0] * 400) == []


def torques_with_d2(d2_nm: list[float]) -> list[float]:
    """A trace whose second differences T_i - 2 T_(i-1) + T_(i-2) are exactly ``d2_nm``."""
    torques = [0.0, 0.0]
    for d2 in d2_nm:
        torques.append(2.0 * torques[-1] - torques[-2] + d2)
    return torques


def test_the_estimate_is_the_median_of_the_first_values_then_steps() -> None:
    d2_nm = [float(v) for v in np.random.default_rng(0).permutation(SEED_SAMPLES) + 1]
    tracker = ExtremumTracker(MotorMotion())
    torques = torques_with_d2([*d2_nm, 1e3])
    for torque_nm in torques[:-1]:
        tracker.torque_noise.add(torque_nm)
    # the upper median of 1 .. SEED_SAMPLES, not the first value alone
    assert tracker.noise_d2_nm == SEED_SAMPLES // 2 + 1
    tracker.torque_noise.add(torques[-1])  # after the start-up: one step of 2 %, O(1)
    assert tracker.noise_d2_nm == (SEED_SAMPLES // 2 + 1) * 1.02
