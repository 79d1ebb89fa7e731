"""The joints of the torque-only benchmark are drawn as they say: drops, families, seeds."""

from __future__ import annotations

import math
import statistics

import pytest

from services.rig.physics import TighteningPhysics
from tests.benchmarks.torque_only_joints import (
    FAMILIES,
    Joint,
    drop_share,
    family_joints,
    mu_slip_for_drop,
)


@pytest.mark.parametrize("share", [0.02, 0.08, 0.25])
def test_mu_slip_is_solved_for_the_drawn_drop(share: float) -> None:
    mu_slip = mu_slip_for_drop(600.0, 80_000.0, 0.011, 0.3, share, 0.15)
    assert 0.0 < mu_slip < 0.3
    assert drop_share(600.0, 80_000.0, 0.011, 0.3, mu_slip, 0.15) == pytest.approx(share)


def true_drops_pct(joint: Joint) -> list[float]:
    """Slip drops of the unstopped joint whose peak is within ±30 % of T*, % of T*."""
    sim = TighteningPhysics(joint.constants, joint.program, joint.rig, seed=joint.seed)
    drops: list[float] = []
    peak = math.nan  # the torque the slip under way started at
    was_slipping = False
    while sim.true_force_n < 1.1 * joint.target_force_n:
        before = sim.true_torque_nm
        sim.advance()
        if sim.slipping and not was_slipping:
            peak = before
        ended = was_slipping and not sim.slipping
        if ended and abs(peak / joint.target_torque_nm - 1.0) <= 0.3:
            drops.append(100.0 * (peak - sim.true_torque_nm) / joint.target_torque_nm)
        was_slipping = sim.slipping
    return drops


@pytest.mark.parametrize("number", [1, 14, 22])
def test_a_drawn_joint_slips_by_about_its_drawn_drop(number: int) -> None:
    # tune-a's joints 1, 14 and 22 stick and slip near the target (drawn 19, 4 and 6.5 %)
    joint = family_joints("tune-a", number + 1)[number]
    drops = true_drops_pct(joint)
    assert len(drops) >= 3
    assert statistics.median(drops) == pytest.approx(100.0 * joint.drop_share, rel=0.25)


def test_families_are_the_same_joints_on_every_call_and_tune_apart_from_judge() -> None:
    assert {role for role, _ in FAMILIES.values()} == {"tune", "judge"}
    first = family_joints("judge-a", 3)
    assert family_joints("judge-a", 3) == first
    assert {j.seed for j in first}.isdisjoint(j.seed for j in family_joints("tune-a", 3))
    with pytest.raises(ValueError, match="unknown family 'judge-z'"):
        family_joints("judge-z", 1)
