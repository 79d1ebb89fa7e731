"""How far eq. 71's model band is from stopping right joints, and how it catches wrong ones.

Run: ``.venv/bin/python tests/benchmarks/bench_band_margin.py [--joints N] [--seed S]
[--slow-ramp-joints N] [--torque-only]``

Two sets of joints, each tightened closed loop by the predictor (force mode;
``--torque-only``: to the torque target without force) until it stops (the
stop latency and settling of the accuracy benchmarks do not matter here):

- **paper's ranges**: the joints, programs and rig seeds of
  ``bench_predictor_accuracy.py`` (``--joints``, ``--seed``), the rig's
  default noise;
- **slow ramps**: joints drawn as the torque-only benchmark draws them
  (``torque_only_joints.py``: drops 2-25 % of the target, μ_stick scatter
  0-5 %, torque noise 0.02-0.3 % of the target) with stick ramps of 10-20
  samples per percent of the target torque (``--slow-ramp-joints``, seed
  :data:`SLOW_RAMP_SEED`): on them the noise is most of what a short period
  shows.

Each joint twice:

- configured with its own constants: every ``constant_out_of_band`` stop is a
  false stop. Printed: the count (with the joint's number and where the stop
  left the target: % of the target torque, torque-only, or force), the events
  the band judged, those it left out for lack of evidence (noise floor not
  settled, a period that was not one stick phase), and the largest share of
  its widened bound any median reached per constant (1.0 = a stop);
- configured wrongly, as ``tests/unit/shared/stickslip/test_model_bands.py`` does
  (μ_slip so low that the configured slips are far larger): the share of
  joints stopped on ``constant_out_of_band``, and how many events it took.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # run as a script: the repo root
from services.rig.physics import TighteningPhysics
from shared.config import Program, RigSection
from shared.model import JointConstants
from shared.stickslip import PredictorCore, PredictorSettings, model_bands
from tests.benchmarks.bench_predictor_accuracy import draw_joint
from tests.benchmarks.torque_only_joints import drawn_joint

WRONG_MU_SLIP_SHARE = 0.4  # the wrong joint's μ_slip as a share of its μ_stick
SLOW_RAMP_SEED = 401
SLOW_RAMPS_SAMPLES_PER_PCT = (10.0, 20.0)


@dataclass(frozen=True)
class BandJoint:
    """A joint, its program and rig, and what it is tightened to."""

    constants: JointConstants
    program: Program
    rig: RigSection
    target_force_n: float
    target_torque_nm: float
    seed: int


@dataclass(frozen=True)
class BandRun:
    reason: str
    error_pct: float  # where the stop left the target (torque-only: torque, else force)
    events: int
    judged: int
    unsettled: int
    not_stick_periods: int
    nearest_edge: dict[int, float]


def paper_joints(count: int, seed: int) -> list[BandJoint]:
    """The joints of ``bench_predictor_accuracy.py``, the rig's default noise."""
    rng = np.random.default_rng(seed)
    drawn = [draw_joint(rng, seed * 1000 + i) for i in range(count)]
    rig = RigSection()
    return [
        BandJoint(j.constants, j.program, rig, j.target_force_n, j.target_torque_nm, j.seed)
        for j in drawn
    ]


def slow_ramp_joints(count: int) -> list[BandJoint]:
    """Joints drawn as the torque-only benchmark's, stick ramps of 10-20 samples per %."""
    rng = np.random.default_rng(SLOW_RAMP_SEED)
    joints = []
    for number in range(count):
        seed = SLOW_RAMP_SEED * 10_000 + number
        j = drawn_joint("slow-ramp", number, rng, seed, SLOW_RAMPS_SAMPLES_PER_PCT)
        joints.append(
            BandJoint(j.constants, j.program, j.rig, j.target_force_n, j.target_torque_nm, seed)
        )
    return joints


def tighten(
    joint: BandJoint, configured: JointConstants, torque_only: bool, evidence: bool = True
) -> BandRun:
    """The predictor with ``configured`` constants on ``joint``'s rig, until it stops.

    ``evidence`` False: every event judged, as before the evidence rules (comparison only).
    """
    core = PredictorCore(
        PredictorSettings(
            target_force_n=None if torque_only else joint.target_force_n,
            target_torque_nm=joint.target_torque_nm if torque_only else None,
            has_force=not torque_only,
            motor_speed_rad_s=joint.program.motor_speed_rad_s,
            constants=configured,
        )
    )
    if not evidence and core.model_bands is not None:
        core.model_bands._noise_settled = True
    sim = TighteningPhysics(joint.constants, joint.program, joint.rig, seed=joint.seed)
    for _ in range(int(joint.program.max_time_s * 1000)):
        m = sim.advance()
        core.update(m.time_s, m.torque_nm, math.nan if torque_only else m.force_n, m.angle_deg)
        if core.decision is not None:
            break
    bands = core.model_bands
    assert bands is not None
    decision = core.decision
    reason = decision.reason if decision is not None else "none"
    if torque_only:
        error = (sim.true_torque_nm - joint.target_torque_nm) / joint.target_torque_nm
    else:
        error = (sim.true_force_n - joint.target_force_n) / joint.target_force_n
    return BandRun(
        reason,
        100.0 * error,
        core.events,
        bands.judged,
        bands.unsettled,
        bands.not_stick_periods,
        dict(bands.nearest_edge),
    )


def wrong(constants: JointConstants) -> JointConstants:
    return replace(constants, mu_slip=WRONG_MU_SLIP_SHARE * constants.mu_stick)


def report(title: str, joints: list[BandJoint], torque_only: bool, evidence: bool) -> None:
    right = [tighten(joint, joint.constants, torque_only, evidence) for joint in joints]
    false_stops = [
        f"#{i} ({run.error_pct:+.1f} %)"
        for i, run in enumerate(right)
        if run.reason == "constant_out_of_band"
    ]
    print(f"{title}, {len(joints)} joints, right constants:")
    print(f"  constant_out_of_band stops: {len(false_stops)} {' '.join(false_stops)}")
    print(
        f"  events {sum(r.events for r in right)}, judged {sum(r.judged for r in right)}, "
        f"not judged: noise floor unsettled {sum(r.unsettled for r in right)}, "
        f"period not one stick phase {sum(r.not_stick_periods for r in right)}"
    )
    for number in (1, 2, 3):
        edges = [r.nearest_edge[number] for r in right]
        worst = max(range(len(edges)), key=lambda i: edges[i])
        print(
            f"  K{number}: largest share of the widened bound {edges[worst]:.2f} (joint {worst}), "
            f"median over joints {statistics.median(edges):.2f}"
        )
    wrong_runs = [tighten(joint, wrong(joint.constants), torque_only, evidence) for joint in joints]
    caught = [r for r in wrong_runs if r.reason == "constant_out_of_band"]
    # joints that stick and slip through their run (judged ≥ 10 times with the right constants)
    stick_slip = [w for r, w in zip(right, wrong_runs, strict=True) if r.judged >= 10]
    caught_stick_slip = [r for r in stick_slip if r.reason == "constant_out_of_band"]
    events = [r.events for r in caught]
    print(f"wrong constants (μ_slip = {WRONG_MU_SLIP_SHARE} μ_stick):")
    print(
        f"  stopped on constant_out_of_band: {len(caught)} of {len(joints)}; "
        f"of the {len(stick_slip)} judged ≥ 10 times when right: {len(caught_stick_slip)}; "
        f"events to the stop: median {statistics.median(events) if events else math.nan}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--joints", type=int, default=100, help="joints of the paper's ranges")
    parser.add_argument("--seed", type=int, default=2018)
    parser.add_argument("--slow-ramp-joints", type=int, default=100, help="slow-ramp joints")
    parser.add_argument("--torque-only", action="store_true", help="torque target, no force")
    parser.add_argument(
        "--without-evidence",
        action="store_true",
        help="judge every event (the rule before its evidence requirements), to compare",
    )
    args = parser.parse_args()
    evidence = not args.without_evidence
    if not evidence:
        model_bands.MIN_STICK_SHARE = -math.inf
    mode = "torque-only" if args.torque_only else "force"
    if args.joints:
        title = f"paper's ranges, seed {args.seed}, {mode}"
        report(title, paper_joints(args.joints, args.seed), args.torque_only, evidence)
    if args.slow_ramp_joints:
        title = f"slow ramps (10-20 samples per % of target), seed {SLOW_RAMP_SEED}, {mode}"
        report(title, slow_ramp_joints(args.slow_ramp_joints), args.torque_only, evidence)


if __name__ == "__main__":
    main()
