"""Stop decisions and robustness of the core on constructed traces."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shared.stickslip import CoreDecision, EventFigures, PredictorCore, PredictorSettings
from tests.support.synthetic_runs import SyntheticTrace, smooth_ramp, staircase


def run(core: PredictorCore, rows: list[tuple[float, float, float, float]]) -> list[object]:
    return [output for row in rows for output in core.update(*row)]


def decisions(outputs: list[object]) -> list[CoreDecision]:
    return [o for o in outputs if isinstance(o, CoreDecision)]


def events(outputs: list[object]) -> list[EventFigures]:
    return [o for o in outputs if isinstance(o, EventFigures)]


def closest_plateau(trace: SyntheticTrace, target: float) -> float:
    return min(trace.plateaus_n, key=lambda f: abs(f - target))


@pytest.mark.parametrize("target", [25_000.0, 30_400.0, 33_000.0])
def test_clean_staircase_stops_on_the_closest_plateau(target: float) -> None:
    trace = staircase(torque_noise_nm=0.2, force_noise_n=30.0)
    core = PredictorCore(PredictorSettings(target_force_n=target))
    outputs = run(core, trace.rows())
    (decision,) = decisions(outputs)
    assert decision.reason in ("plateau_closest", "target_reached")
    assert decision.force_n == pytest.approx(closest_plateau(trace, target), abs=150.0)
    assert core.events >= 30


def test_every_slip_of_the_staircase_is_an_event() -> None:
    trace = staircase(torque_noise_nm=0.2, force_noise_n=30.0)
    core = PredictorCore(PredictorSettings(target_force_n=None, target_torque_nm=None))
    found = events(run(core, trace.rows()))
    assert len(found) == len(trace.plateaus_n) - 1
    assert all(e.torque_drop_nm > 1.0 for e in found)
    later = found[5:]
    assert all(e.f_ss_hz is not None and 20.0 < e.f_ss_hz < 100.0 for e in later)
    assert all(e.force_step_n is not None and e.force_step_n > 0 for e in later)
    assert found[-1].process_intensity == pytest.approx(
        sum(e.intensity for e in found if e.intensity is not None)
    )


@pytest.mark.parametrize("k_e, speed", [(200.0, 0.3), (2000.0, 0.2), (1000.0, 0.1)])
def test_events_found_from_slow_to_fast_stick_slip(k_e: float, speed: float) -> None:
    trace = staircase(k_e=k_e, speed_rad_s=speed, torque_noise_nm=0.2, force_noise_n=30.0)
    core = PredictorCore(PredictorSettings(target_force_n=None))
    found = events(run(core, trace.rows()))
    assert len(found) >= len(trace.plateaus_n) - 2


def test_torque_only_stops_near_the_torque_target() -> None:
    trace = staircase(torque_noise_nm=0.2)
    core = PredictorCore(
        PredictorSettings(target_torque_nm=120.0, has_force=False, torque_plateau_rule=True)
    )
    rows = [(t, tq, math.nan, a) for t, tq, _, a in trace.rows()]
    (decision,) = decisions(run(core, rows))
    assert decision.reason == "plateau_closest"
    assert decision.force_n is None
    # a torque prediction is named as one (it was predicted_force_n, holding Nm)
    assert decision.predicted_force_n is None
    assert decision.predicted_torque_nm is not None
    assert abs(decision.predicted_torque_nm - 120.0) < 5.0


def test_smooth_ramp_without_stick_slip_stops_on_target() -> None:
    trace = smooth_ramp()
    core = PredictorCore(PredictorSettings(target_force_n=40_000.0))
    outputs = run(core, trace.rows())
    assert events(outputs) == []
    (decision,) = decisions(outputs)
    assert decision.reason == "target_reached"
    assert decision.force_n == pytest.approx(40_000.0, abs=200.0)


def test_noise_alone_never_stops() -> None:
    rng = np.random.default_rng(3)
    core = PredictorCore(PredictorSettings(target_force_n=40_000.0, target_torque_nm=150.0))
    rows = [
        (i * 1e-3, 50.0 + rng.normal(0, 2.0), 20_000.0 + rng.normal(0, 50.0), 0.0)
        for i in range(3000)
    ]
    assert decisions(run(core, rows)) == []


def test_hard_limits_stop_with_their_reason() -> None:
    core = PredictorCore(PredictorSettings(target_force_n=90_000.0, max_torque_nm=100.0))
    rows = [(i * 1e-3, float(i), 1000.0, 0.0) for i in range(200)]
    (decision,) = decisions(run(core, rows))
    assert decision.reason == "torque_limit"
    assert decision.torque_nm >= 100.0
    core = PredictorCore(PredictorSettings(target_force_n=90_000.0, max_angle_deg=30.0))
    rows = [(i * 1e-3, 1.0, 1000.0, 100.0 + i) for i in range(200)]
    assert decisions(run(core, rows))[0].reason == "angle_limit"
    core = PredictorCore(PredictorSettings(target_force_n=90_000.0, max_force_n=5000.0))
    rows = [(i * 1e-3, 1.0, 100.0 * i, 0.0) for i in range(200)]
    assert decisions(run(core, rows))[0].reason == "force_limit"


def test_intensity_limit_eq_70() -> None:
    trace = staircase()
    core = PredictorCore(PredictorSettings(target_force_n=None, max_process_intensity=50_000.0))
    (decision,) = decisions(run(core, trace.rows()))
    assert decision.reason == "intensity_limit"
    assert core.process_intensity > 50_000.0


def test_constant_out_of_band_eq_71_only_when_configured() -> None:
    trace = staircase(force_noise_n=30.0)
    # A staircase that changes joint half way: much stiffer screw after 0.6 s.
    second = staircase(k_s=300_000.0, start_force_n=trace.plateaus_n[-1], force_noise_n=30.0)
    rows = trace.rows()[:600] + [(t + 0.6, tq, f, a) for t, tq, f, a in second.rows()[:300]]
    quiet = PredictorCore(PredictorSettings(target_force_n=None, motor_speed_rad_s=0.5))
    assert decisions(run(quiet, rows)) == []
    banded = PredictorCore(
        PredictorSettings(target_force_n=None, motor_speed_rad_s=0.5, constant_band=0.5)
    )
    (decision,) = decisions(run(banded, rows))
    assert decision.reason == "constant_out_of_band"


def test_bad_input_is_counted_and_never_crashes() -> None:
    trace = staircase(torque_noise_nm=0.2, force_noise_n=30.0)
    rows = trace.rows()
    rng = np.random.default_rng(1)
    bad: list[tuple[float, float, float, float]] = []
    for i, (t, tq, f, a) in enumerate(rows):
        if i % 97 == 0:
            bad.append((t, math.nan, f, a))  # NaN torque: dropped
        elif i % 89 == 0:
            bad.append((t, tq, math.nan, a))  # NaN force: held
        elif i % 53 == 0:
            bad.append((t - 0.01, tq, f, a))  # out of order: dropped
        else:
            bad.append((t, tq, f, a))
        if i % 61 == 0:
            bad.append((t, tq, f, a))  # repeated timestamp
    gap = [row for row in bad if not 0.300 < row[0] < 0.330]  # a 30 ms gap
    core = PredictorCore(PredictorSettings(target_force_n=30_400.0))
    outputs = run(core, gap)
    report = core.input_report
    assert report.bad_torque > 0 and report.held_force > 0 and report.out_of_order > 0
    assert report.repeated_time > 0 and report.gaps == 1
    (decision,) = decisions(outputs)
    assert decision.reason in ("plateau_closest", "target_reached")
    assert decision.force_n == pytest.approx(closest_plateau(trace, 30_400.0), abs=150.0)
    assert rng is not None


def test_five_samples_and_empty_input() -> None:
    core = PredictorCore(PredictorSettings(target_force_n=40_000.0))
    outputs = run(core, [(i * 1e-3, 10.0 + i, 20_000.0, 0.0) for i in range(5)])
    assert outputs == []
    assert core.input_report.accepted == 5


def test_input_fault_only_when_input_stays_unusable() -> None:
    core = PredictorCore(PredictorSettings(target_force_n=40_000.0, fault_samples=100))
    rows = [(i * 1e-3, 10.0, 20_000.0, 0.0) for i in range(50)]
    rows += [(0.05 + i * 1e-3, math.nan, math.nan, 0.0) for i in range(99)]
    assert decisions(run(core, rows)) == []
    (decision,) = decisions(run(core, [(0.2, math.nan, math.nan, 0.0)] * 5))
    assert decision.reason == "input_fault"


def test_one_decision_per_run() -> None:
    core = PredictorCore(PredictorSettings(target_force_n=20_000.0, max_torque_nm=1.0))
    outputs = run(core, smooth_ramp().rows())
    assert len(decisions(outputs)) == 1


def test_torque_target_stops_on_a_stick_ramp_at_the_target() -> None:
    """Without eq. 64 (the default) a torque target is met on a stick ramp, not at a trough."""
    trace = staircase(torque_noise_nm=0.2)
    core = PredictorCore(PredictorSettings(target_torque_nm=120.0, has_force=False))
    rows = [(t, tq, math.nan, a) for t, tq, _, a in trace.rows()]
    (decision,) = decisions(run(core, rows))
    assert decision.reason == "target_reached"
    assert decision.torque_nm == pytest.approx(120.0, abs=1.5)


def first_stop(policy: object, ramp: list[tuple[float, float]]) -> float | None:
    from shared.stickslip import StopPolicy

    assert isinstance(policy, StopPolicy)
    return next((tq for t, tq in ramp if policy.on_sample(t, tq, None, 0.0) is not None), None)


def test_a_halt_plan_moves_the_torque_stop_and_holds_one_phase_only() -> None:
    from shared.stickslip import StopPolicy

    settings = PredictorSettings(target_torque_nm=100.0, has_force=False)
    ramp = [(i * 1e-3, 95.0 + 0.5 * i) for i in range(30)]
    above = StopPolicy(settings)
    above.plan_halt(103.0, 0.5, 8.0, 100)  # the next phase is the safer one: ride past
    assert first_stop(above, ramp) == pytest.approx(102.5)  # 102.5 + 0.5 · 1.5 ≥ 103
    below = StopPolicy(settings)
    below.plan_halt(98.0, 0.5, 8.0, 100)  # this phase slips at the target: stop below
    assert first_stop(below, ramp) == pytest.approx(97.5)
    expired = StopPolicy(settings)
    expired.plan_halt(103.0, 0.5, 8.0, 3)  # outlived: back to the target rules
    stop = first_stop(expired, ramp)
    assert stop is not None and stop <= 101.0
    slipped = StopPolicy(settings)
    slipped.plan_halt(103.0, 0.5, 8.0, 100)
    # the phase slips (undetected yet) at 99 Nm: the new phase halts on the target
    ramp = [(i * 1e-3, 95.0 + 0.5 * i) for i in range(9)]
    ramp += [(0.01 + i * 1e-3, 92.0 + 0.5 * i) for i in range(30)]
    assert first_stop(slipped, ramp) == pytest.approx(99.5)
    unplanned = StopPolicy(settings)
    unplanned.plan_halt(None)
    stop = first_stop(unplanned, [(i * 1e-3, 95.0 + 0.5 * i) for i in range(30)])
    assert stop is not None and 99.0 <= stop <= 101.5
    spiked = StopPolicy(settings)
    spiked.plan_halt(100.0, 0.5, 8.0, 100)
    ramp = [(i * 1e-3, 95.0 + 0.5 * i + (3.0 if i == 4 else 0.0)) for i in range(30)]
    assert first_stop(spiked, ramp) == pytest.approx(99.5)  # the spike at 97 + 3 is not it


def test_a_halt_plan_never_aims_past_the_torque_limit() -> None:
    """A program whose limit sits within the plan's reach (target 100, limit 102): the plan
    is capped below the limit, so the stop is the planned one, never a limit fault."""
    from shared.stickslip import StopPolicy

    settings = PredictorSettings(target_torque_nm=100.0, has_force=False, max_torque_nm=102.0)
    policy = StopPolicy(settings)
    policy.plan_halt(103.0, 0.5, 8.0, 100)
    ramp = [(i * 1e-3, 95.0 + 0.5 * i) for i in range(30)]
    decision = next(d for t, tq in ramp if (d := policy.on_sample(t, tq, None, 0.0)))
    assert decision.reason == "target_reached"
    assert decision.torque_nm < 102.0
