"""Closed-loop stop accuracy of the predictor against the rig physics (not a test).

Run: ``.venv/bin/python tests/benchmarks/bench_predictor_accuracy.py [--joints N]``

For each of N joints drawn across the paper's ranges (k_e 200-2000 Nm/rad,
k_s 30-180 kN/rad, μ_stick 0.1-0.4 with μ_slip 2-8 % below, motor speeds
0.1-2 rad/s log-uniform, targets 30-60 kN, sensor noise), every policy
tightens the same joint (same seed, so the same friction draws):

- conventional: halt when the measured force first reaches the target;
- predictor:    halt one sample after the core's stop decision;
- oracle:       the plateau closest to the target of an unstopped run;

and the same in torque-only mode (target torque = F_target · r · μ_stick,
the peak torque of the plateau at the target; no force given to the core).
The figure is |F_reached - F_target| / F_target after the slip under way
has finished. Plateau predictors compared: poly2 (paper Sec. 6.4), linear,
mean_step (see services/predictor/core/regression.py).
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from dataclasses import dataclass

import numpy as np

from services.predictor.core import PredictorCore, PredictorSettings
from services.predictor.core.settings import PlateauMethod
from services.rig.physics import TighteningPhysics
from shared.config import Program, RigSection
from shared.model import JointConstants

SETTLE_SAMPLES = 300


@dataclass(frozen=True)
class Joint:
    constants: JointConstants
    program: Program
    target_force_n: float
    target_torque_nm: float
    seed: int


def draw_joint(rng: np.random.Generator, seed: int) -> Joint:
    k_e = rng.uniform(200.0, 2000.0)
    k_s = rng.uniform(30_000.0, 180_000.0)
    r = rng.uniform(0.008, 0.014)
    mu_stick = rng.uniform(0.1, 0.4)
    mu_slip = mu_stick * (1.0 - rng.uniform(0.02, 0.08))
    speed = math.exp(rng.uniform(math.log(0.1), math.log(2.0)))
    target = rng.uniform(30_000.0, 60_000.0)
    start = 0.25 * target
    # time to the target: twist of the extension plus turning of the screw (eqs. 27-29)
    expected_s = (target * r * mu_stick / k_e + (target - start) / k_s) / speed
    program = Program(
        id=1,
        name="bench",
        target_force_n=target,
        motor_speed_rad_s=speed,
        start_force_n=start,
        max_torque_nm=10_000.0,
        max_force_n=3.0 * target,
        max_angle_deg=1e6,
        max_time_s=3.0 * expected_s + 1.0,
    )
    constants = JointConstants(k_e, k_s, r, mu_stick, mu_slip)
    return Joint(constants, program, target, target * r * mu_stick, seed)


def physics(joint: Joint) -> TighteningPhysics:
    return TighteningPhysics(joint.constants, joint.program, RigSection(), seed=joint.seed)


def finish(sim: TighteningPhysics) -> float:
    sim.halt_motor()
    for _ in range(SETTLE_SAMPLES):
        if sim.settled:
            break
        sim.advance()
    return sim.true_force_n


def max_samples(joint: Joint) -> int:
    return int(joint.program.max_time_s * 1000)


def oracle(joint: Joint, conventional_n: float) -> float:
    """The closest plateau of an unstopped run; a joint that slides smoothly (no
    stick-slip, so no plateaus near the target) can stop anywhere: there the
    conventional stop is as good as it gets."""
    sim = physics(joint)
    for _ in range(max_samples(joint)):
        sim.advance()
        if sim.true_force_n > 1.5 * joint.target_force_n:
            break
    best = min(sim.plateau_forces_n, key=lambda f: abs(f - joint.target_force_n))
    return min(best, conventional_n, key=lambda f: abs(f - joint.target_force_n))


def conventional(joint: Joint, torque_only: bool) -> float:
    sim = physics(joint)
    for _ in range(max_samples(joint)):
        m = sim.advance()
        if torque_only:
            reached = m.torque_nm >= joint.target_torque_nm
        else:
            reached = m.force_n >= joint.target_force_n
        if reached:
            break
    return finish(sim)


def predictor(joint: Joint, torque_only: bool, method: PlateauMethod) -> tuple[float, str]:
    settings = PredictorSettings(
        target_force_n=None if torque_only else joint.target_force_n,
        target_torque_nm=joint.target_torque_nm if torque_only else None,
        has_force=not torque_only,
        motor_speed_rad_s=joint.program.motor_speed_rad_s,
        plateau_method=method,
    )
    core = PredictorCore(settings)
    sim = physics(joint)
    reason = "none"
    for _ in range(max_samples(joint)):
        m = sim.advance()
        force = math.nan if torque_only else m.force_n
        core.update(m.time_s, m.torque_nm, force, m.angle_deg)
        if core.decision is not None:
            reason = core.decision.reason
            sim.advance()  # halt one sample after the decision
            break
    return finish(sim), reason


def error(joint: Joint, reached_n: float) -> float:
    return abs(reached_n - joint.target_force_n) / joint.target_force_n


def stats(values: list[float]) -> str:
    ordered = sorted(values)
    p95 = ordered[min(len(ordered) - 1, int(0.95 * len(ordered)))]
    return (
        f"{100 * statistics.fmean(values):7.2f} {100 * statistics.median(values):7.2f} "
        f"{100 * p95:7.2f}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--joints", type=int, default=100)
    parser.add_argument("--seed", type=int, default=2018)
    parser.add_argument("--methods", default="poly2,linear,mean_step")
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    joints = [draw_joint(rng, args.seed * 1000 + i) for i in range(args.joints)]
    methods: list[PlateauMethod] = args.methods.split(",")
    rows: dict[str, list[float]] = {}
    reasons: dict[str, dict[str, int]] = {}
    started = time.process_time()
    wall = time.perf_counter()
    for joint in joints:
        conventional_n = conventional(joint, torque_only=False)
        rows.setdefault("oracle", []).append(error(joint, oracle(joint, conventional_n)))
        for torque_only in (False, True):
            mode = "torque-only" if torque_only else "force"
            rows.setdefault(f"conventional {mode}", []).append(
                error(joint, conventional(joint, torque_only))
            )
            for method in methods:
                reached, reason = predictor(joint, torque_only, method)
                name = f"predictor {mode} {method}"
                rows.setdefault(name, []).append(error(joint, reached))
                counts = reasons.setdefault(name, {})
                counts[reason] = counts.get(reason, 0) + 1
    cpu_s = time.process_time() - started
    print(f"{len(joints)} joints, {cpu_s:.1f} s CPU, {time.perf_counter() - wall:.1f} s wall")
    print(f"{'policy':34s} {'mean%':>7s} {'median%':>7s} {'p95%':>7s}  ratio/oracle ratio/conv")
    oracle_mean = statistics.fmean(rows["oracle"])
    for name, values in rows.items():
        conv = rows.get(f"conventional {'torque-only' if 'torque-only' in name else 'force'}")
        ratio_conv = statistics.fmean(values) / statistics.fmean(conv) if conv else math.nan
        print(
            f"{name:34s} {stats(values)}  {statistics.fmean(values) / oracle_mean:6.2f}"
            f"       {ratio_conv:5.2f}  {reasons.get(name, '')}"
        )


if __name__ == "__main__":
    main()
