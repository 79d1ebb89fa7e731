"""The simulated tightening against the paper's analytical model (Sections 3.1, 5.2)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from services.rig.physics import Measurement, TighteningPhysics
from tests.support.rig_fixtures import constants, paper_program, paper_rig, quiet_rig


def run_until_force(physics: TighteningPhysics, force_n: float, max_samples: int) -> None:
    for _ in range(max_samples):
        if physics.true_force_n >= force_n:
            return
        physics.advance()
    raise AssertionError(f"force {force_n} N not reached in {max_samples} samples")


def test_stick_peaks_follow_the_stick_limit() -> None:
    """Torque peaks of each stick phase are μ_stick · F · r (eq. 9), F the plateau."""
    joint = constants()
    physics = TighteningPhysics(joint, paper_program(), quiet_rig(), seed=1, sample_period_s=1e-4)
    peak_by_phase: dict[int, float] = {}
    for _ in range(10_000):
        measurement = physics.advance()
        if not physics.slipping:
            phase = len(physics.plateau_forces_n) - 1
            peak_by_phase[phase] = max(peak_by_phase.get(phase, 0.0), measurement.torque_nm)
    plateaus = physics.plateau_forces_n
    completed = range(1, physics.slip_count)  # phases that ended in a slip, start excluded
    assert len(completed) > 10
    # within one sample of the linear torque rise k_e·w·Δt below the limit
    rise_per_sample_nm = joint.k_e_nm_per_rad * paper_program().motor_speed_rad_s * 1e-4
    for phase in completed:
        limit_nm = joint.mu_stick * plateaus[phase] * joint.r_m
        assert limit_nm - rise_per_sample_nm - 1e-9 <= peak_by_phase[phase] <= limit_nm + 1e-9


def test_slip_step_and_torque_drop_match_the_damped_oscillator() -> None:
    """ΔF = (1 + q) · k_s · Δμ F r / K with q the overshoot of the damped slip; ΔT = k_e Δφ_b.

    With the motor nearly standing during a slip, the screw starts |x0| = Δμ F r / K
    below the slip equilibrium (eqs. 9, 10, 17) and overshoots it by q · |x0|,
    q = exp(−ζπ/√(1−ζ²)); the torque drops by k_e times the slip angle (eq. 21).
    """
    joint = constants()
    rig = quiet_rig(damping_ratio=0.2)
    slow = paper_program(motor_speed_rad_s=0.01)
    physics = TighteningPhysics(joint, slow, rig, seed=1, sample_period_s=1e-3)
    stick_start_torque: dict[int, float] = {}
    for _ in range(20_000):
        physics.advance()
        phase = len(physics.plateau_forces_n) - 1
        if not physics.slipping and phase not in stick_start_torque:
            stick_start_torque[phase] = physics.true_torque_nm
        if physics.slip_count >= 12:
            break
    stiffness = joint.k_e_nm_per_rad + joint.mu_slip * joint.k_s_n_per_rad * joint.r_m
    overshoot = math.exp(-rig.damping_ratio * math.pi / math.sqrt(1 - rig.damping_ratio**2))
    delta_mu = joint.mu_stick - joint.mu_slip
    plateaus = physics.plateau_forces_n
    for phase in range(1, len(plateaus) - 1):
        force_n = plateaus[phase]
        step_n = plateaus[phase + 1] - force_n
        expected_step_n = (1 + overshoot) * joint.k_s_n_per_rad * delta_mu * force_n * joint.r_m
        assert step_n == pytest.approx(expected_step_n / stiffness, rel=0.02)
        peak_nm = joint.mu_stick * force_n * joint.r_m
        drop_nm = joint.k_e_nm_per_rad * step_n / joint.k_s_n_per_rad
        assert stick_start_torque[phase + 1] == pytest.approx(peak_nm - drop_nm, abs=0.1)


def test_force_steps_within_the_paper_bounds() -> None:
    """ΔF_min = Δφ_b k_s ≤ ΔF ≤ φ_0,stick k_s = ΔF_max (eqs. 16-19, 23, 24)."""
    joint = constants()
    physics = TighteningPhysics(joint, paper_program(), quiet_rig(), seed=3)
    run_until_force(physics, 56_000.0, 4_000)
    k_s, k_e, r = joint.k_s_n_per_rad, joint.k_e_nm_per_rad, joint.r_m
    gamma_stick = k_e / (k_e + k_s * r * joint.mu_stick)  # eq. 16
    gamma_slip = k_e / (k_e + k_s * r * joint.mu_slip)  # eq. 17
    plateaus = physics.plateau_forces_n
    assert len(plateaus) > 20
    for before_n, after_n in itertools.pairwise(plateaus[1:]):
        motor_angle_rad = before_n / k_s / gamma_stick  # φ_b,min = γ_stick φ_m at the slip
        step_min_n = motor_angle_rad * (gamma_slip - gamma_stick) * k_s  # eqs. 18, 23
        step_max_n = motor_angle_rad * (1 - gamma_stick) * k_s  # eqs. 19, 24
        assert step_min_n <= after_n - before_n <= step_max_n


def test_preload_never_decreases() -> None:
    physics = TighteningPhysics(constants(), paper_program(), quiet_rig(mu_stick_scatter=0.05), 9)
    forces = []
    for _ in range(1500):
        physics.advance()
        forces.append(physics.true_force_n)
    assert np.all(np.diff(forces) >= 0.0)
    assert np.all(np.diff(physics.plateau_forces_n) > 0.0)
    assert forces[-1] > forces[0] + 20_000.0


def test_halt_lets_the_slip_finish_then_nothing_moves() -> None:
    joint = constants()
    physics = TighteningPhysics(joint, paper_program(), quiet_rig(), seed=2, sample_period_s=1e-4)
    while physics.slip_count < 5 or not physics.slipping:
        physics.advance()
    force_at_halt_n = physics.true_force_n
    physics.halt_motor()
    assert not physics.motor_running
    while not physics.settled:
        physics.advance()
    settled_force_n = physics.true_force_n
    settled_torque_nm = physics.true_torque_nm
    plateaus = len(physics.plateau_forces_n)
    for _ in range(2000):
        physics.advance()
    assert settled_force_n > force_at_halt_n  # the slip under way finished
    assert physics.true_force_n == settled_force_n
    assert physics.true_torque_nm == settled_torque_nm
    assert len(physics.plateau_forces_n) == plateaus
    assert physics.slip_count == 5


def test_same_seed_same_run_other_seed_other_run() -> None:
    def measurements(seed: int) -> list[Measurement]:
        physics = TighteningPhysics(constants(), paper_program(), paper_rig(), seed)
        return [physics.advance() for _ in range(400)]

    assert measurements(11) == measurements(11)
    assert measurements(11) != measurements(12)


def test_friction_draws_do_not_depend_on_sampling_noise_or_halting() -> None:
    """The j-th stick phase has the same friction whatever was sampled or stopped."""
    joint = constants()
    program = paper_program()
    rig = paper_rig()
    full = TighteningPhysics(joint, program, rig, seed=5, sample_period_s=1e-3)
    run_until_force(full, 56_000.0, 4_000)
    # other sample period: a different number of noise draws between friction draws
    fine = TighteningPhysics(joint, program, rig, seed=5, sample_period_s=2.5e-4)
    run_until_force(fine, 56_000.0, 16_000)
    phases = min(len(full.plateau_forces_n), len(fine.plateau_forces_n)) - 1
    assert phases > 20
    assert fine.plateau_forces_n[:phases] == pytest.approx(full.plateau_forces_n[:phases], 1e-9)
    # halted early: every stick phase before the halt is the same joint
    halted = TighteningPhysics(joint, program, rig, seed=5, sample_period_s=1e-3)
    run_until_force(halted, 30_000.0, 4_000)
    halted.halt_motor()
    before_halt = len(halted.plateau_forces_n) - 1  # the last phase may follow the halt
    for _ in range(100):
        halted.advance()
    assert halted.plateau_forces_n[:before_halt] == full.plateau_forces_n[:before_halt]


def test_stick_slip_frequency_is_tens_of_hertz() -> None:
    """Paper Section 5.2: 10-40 ms between events for this joint at 0.5 rad/s."""
    physics = TighteningPhysics(constants(), paper_program(), paper_rig(), seed=4)
    slip_times_s: list[float] = []
    while physics.true_force_n < 56_000.0:
        physics.advance()
        if physics.slip_count > len(slip_times_s):
            slip_times_s.append(physics.time_s)
    intervals_s = np.diff(slip_times_s)
    assert len(intervals_s) > 20
    assert float(np.min(intervals_s)) > 0.005
    assert float(np.max(intervals_s)) < 0.15
    assert 0.01 <= float(np.median(intervals_s)) <= 0.06


def test_angle_sensor_is_the_motor_angle_since_start() -> None:
    program = paper_program()
    physics = TighteningPhysics(constants(), program, quiet_rig(), seed=1)
    for _ in range(100):
        measurement = physics.advance()
    assert measurement.time_s == pytest.approx(0.1)
    assert measurement.angle_deg == pytest.approx(math.degrees(program.motor_speed_rad_s * 0.1))
