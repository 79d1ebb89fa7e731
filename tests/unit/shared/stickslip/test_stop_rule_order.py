"""The order of the stop rules (shared/stickslip/stop_policy.py): the first that fires
on a sample or an event is the run's one decision, whatever fires after it."""

from __future__ import annotations

import pytest

from shared.stickslip import PredictorSettings, StopPolicy

SETTINGS = PredictorSettings(
    target_force_n=50_000.0,
    max_torque_nm=100.0,
    max_process_intensity=100.0,
    constant_band=0.1,
    constant_window=3,
)
STEADY = (1.0, 1.0, 1.0)
OFF = (2.0, 1.0, 1.0)  # K1 twice its running mean: out of a 10 % band


def last_event(intensity: float, constants: tuple[float, float, float]) -> str | None:
    """Three quiet events, then one on which the plateau rule fires (the next plateau,
    52 kN, is farther from 50 kN than this one, 49 kN) together with whatever else."""
    policy = StopPolicy(SETTINGS)
    for j in range(3):
        quiet = policy.on_event(0.1 * j, 50.0, 40_000.0, 41_000.0, None, None, 0.0, STEADY)
        assert quiet is None
    decision = policy.on_event(0.4, 50.0, 49_000.0, 52_000.0, None, None, intensity, constants)
    assert policy.on_event(0.5, 50.0, 49_000.0, 52_000.0, None, None, 1e9, OFF) is None  # latched
    return decision.reason if decision is not None else None


@pytest.mark.parametrize(
    ("intensity", "constants", "reason"),
    [
        (200.0, OFF, "intensity_limit"),  # eq. 70 before eq. 71 before eqs. 64/65
        (0.0, OFF, "constant_out_of_band"),
        (0.0, STEADY, "plateau_closest"),
    ],
)
def test_per_event_rules_in_order(
    intensity: float, constants: tuple[float, float, float], reason: str
) -> None:
    assert last_event(intensity, constants) == reason


def test_a_hard_limit_comes_before_the_target_on_the_same_sample() -> None:
    policy = StopPolicy(SETTINGS)
    reasons = [policy.on_sample(i * 1e-3, 150.0, 60_000.0, 10.0) for i in range(4)]
    decided = [d.reason for d in reasons if d is not None]
    assert decided == ["torque_limit"]
