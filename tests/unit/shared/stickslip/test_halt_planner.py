"""The torque halt level of :mod:`shared.stickslip.halt_planner`, by hand."""

from __future__ import annotations

import math

import pytest

from shared.stickslip import MIN_EVENTS, HaltPlanner, best_halt, expected_error


def phi(z: float) -> float:
    return 0.5 * (1.0 + math.erf(z / math.sqrt(2.0)))


def test_expected_error_by_hand() -> None:
    # H = P̂ = T* = 100, σ 1, r 0.5, ΔT 8, e_next 0.1:
    # slipped before Φ(-0.5) · 0.1, during (0.5 - Φ(-0.5)) · |100 - 8 - 100|, sticks 0.5 · 0
    by_hand = phi(-0.5) * 0.1 + (0.5 - phi(-0.5)) * 8.0
    assert expected_error(100.0, 100.0, 1.0, 0.5, 8.0, 100.0, 0.1) == pytest.approx(by_hand)
    # far above the slip: sticks for sure, the error is the distance to the target
    assert expected_error(90.0, 120.0, 1.0, 0.5, 8.0, 100.0, 0.1) == pytest.approx(10.0)


def test_best_halt_is_the_target_when_the_slip_is_far_above() -> None:
    assert best_halt(110.0, 1.0, 0.5, 8.0, 100.0, 0.1) == (100.0, pytest.approx(0.0))


def test_a_slip_predicted_at_the_target_waits_for_the_next_phase_if_it_is_clean() -> None:
    halt, error = best_halt(100.0, 1.0, 0.5, 8.0, 100.0, 0.1)
    assert halt > 100.0 + 3.0  # ride past: the slip comes first, the next phase crosses clean
    assert error == pytest.approx(0.1, abs=0.01)


def test_a_slip_predicted_at_the_target_stops_below_if_the_next_phase_is_worse() -> None:
    halt, error = best_halt(100.5, 1.0, 0.5, 8.0, 100.0, 5.0)
    assert 97.0 < halt < 100.0
    assert error < 5.0


def feed_sawtooth(planner: HaltPlanner, events: int, top_nm: float) -> float | None:
    """Peaks rising 1 Nm per event to ``top_nm``, drop 8 Nm, 20 samples per stick phase."""
    plan = None
    for j in range(events):
        peak = top_nm - (events - 1 - j)
        index = 25 * j + 20
        plan = planner.on_event(index, peak, index + 5, peak - 8.0, [peak + 1, peak + 2, peak + 3])
    return plan


def test_planner_measures_rate_and_drop_and_waits_for_enough_events() -> None:
    planner = HaltPlanner(100.0)
    assert feed_sawtooth(planner, MIN_EVENTS - 1, 99.0) is None
    assert planner.drop_nm == pytest.approx(8.0)
    # trough of j-1 at index 25j, 92 - 1 Nm; peak j at 25j + 20: (peak - trough) / 20 samples
    assert planner.rate_nm_per_sample == pytest.approx(9.0 / 20.0)


def test_planner_plans_near_the_target_only() -> None:
    near = HaltPlanner(100.0)
    plan = feed_sawtooth(near, 8, 99.0)  # next peak predicted at 100: slip risk
    assert plan is not None and plan != 100.0
    far = HaltPlanner(100.0)
    assert feed_sawtooth(far, 8, 60.0) is None  # far below: no plan, the usual rules


def test_planner_ignores_implausible_input() -> None:
    planner = HaltPlanner(100.0)
    feed_sawtooth(planner, 8, 99.0)
    assert planner.on_event(300, 99.0, 305, 91.0, [math.nan, 100.0, 101.0]) is None
    assert planner.on_event(330, 99.0, 335, 91.0, []) is None


def test_a_torque_target_at_a_slip_is_not_halted_into_the_slip() -> None:
    """The target is just above the peak of one stick phase: deciding on the peak sample
    (the ramp's projection reaches the target there) would halt inside the slip."""
    from shared.stickslip import CoreDecision, PredictorCore, PredictorSettings
    from tests.support.synthetic_runs import staircase

    clean = staircase()
    torque = clean.torque_nm
    peaks = [i for i in range(1, len(torque) - 1) if torque[i + 1] < torque[i]]
    for peak in peaks[10:14]:
        target = float(torque[peak] + 1.2 * (torque[peak] - torque[peak - 1]))
        noisy = staircase(torque_noise_nm=0.2, seed=peak)
        core = PredictorCore(PredictorSettings(target_torque_nm=target, has_force=False))
        decided = None
        for index, (t, tq, _, angle) in enumerate(noisy.rows()):
            if any(isinstance(o, CoreDecision) for o in core.update(t, tq, math.nan, angle)):
                decided = index
                break
        assert decided is not None
        halted_nm = float(torque[decided + 1])  # the motor turns one more sample
        assert halted_nm >= float(torque[decided]), "halted during a slip"
        assert abs(halted_nm - target) / target < 0.015
