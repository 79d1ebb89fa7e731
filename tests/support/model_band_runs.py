"""The predictor core over a simulated joint: what it decides against a joint model."""

from __future__ import annotations

import math

from services.rig.physics import TighteningPhysics
from shared.config import Program, RigSection
from shared.model import JointConstants
from shared.stickslip import (
    CoreDecision,
    PredictorCore,
    PredictorSettings,
)
from tests.support import factories

#: the joint of synthetic.staircase()'s defaults
TRACE_JOINT = JointConstants(600.0, 80_000.0, 0.01, 0.36, 0.33)


def drawn_program(speed_rad_s: float, target_n: float, max_time_s: float) -> Program:
    """The program of a joint the accuracy benchmark draws (bench_predictor_accuracy.py):
    to ``target_n`` from a quarter of it, the hard limits far from the run."""
    return factories.program(
        name="bench",
        target_force_n=target_n,
        target_torque_nm=None,
        motor_speed_rad_s=speed_rad_s,
        start_force_n=0.25 * target_n,
        max_torque_nm=10_000.0,
        max_force_n=3.0 * target_n,
        max_angle_deg=1e6,
        max_time_s=max_time_s,
    )


def rig_decision(
    constants: JointConstants, program: Program, rig: RigSection, torque_only: bool, seed: int
) -> CoreDecision | None:
    target_force = program.target_force_n
    assert target_force is not None
    core = PredictorCore(
        PredictorSettings(
            target_force_n=None if torque_only else target_force,
            target_torque_nm=target_force * constants.r_m * constants.mu_stick,
            has_force=not torque_only,
            motor_speed_rad_s=program.motor_speed_rad_s,
            constants=constants,
        )
    )
    sim = TighteningPhysics(constants, program, rig, seed=seed)
    for _ in range(int(program.max_time_s * 1000)):
        m = sim.advance()
        force = math.nan if torque_only else m.force_n
        core.update(m.time_s, m.torque_nm, force, m.angle_deg)
        if core.decision is not None:
            return core.decision
    return None
