"""Closed-loop stop accuracy of the predictor against the rig physics (not a test).

Run: ``.venv/bin/python tests/benchmarks/bench_predictor_accuracy.py [--joints N] [--per-joint]``

For each of N joints drawn across the paper's ranges (k_e 200-2000 Nm/rad,
k_s 30-180 kN/rad, μ_stick 0.1-0.4 with μ_slip 2-8 % below, motor speeds
0.1-2 rad/s log-uniform, targets 30-60 kN, sensor noise), every policy
tightens the same joint (same seed, so the same friction draws and noise):

- conventional: stop when the measured force (torque) first reaches the target;
- predictor:    stop on the core's decision;
- oracle:       the best reachable end: the rig is copied at every stick phase
                and at every sample within ±ORACLE_BAND of the target of an
                unstopped run, halted there and settled; the end closest to
                the target wins (for a joint that slides smoothly this is the
                best sample to halt on, not a plateau).

Conventional and predictor have the same stop latency: the motor halts one
sample after the sample that triggered the stop (the controller's reaction).
The predictor is given the joint's constants, as the live service gives it
the station's joint (the eq. 71 model band is on; ``--no-joint``: off).

Force mode: the figure is |F_reached - F_target| / F_target of the true force
once everything settled.

Torque-only mode: the program's target is a torque, T_target = F_target · r ·
μ_stick (the peak torque of the plateau at the target); no force is given to
the core. A torque-only station controls torque, so its figure is
|T_reached - T_target| / T_target with T_reached the settled true torque of
the extension after the halt, against the *torque* oracle (the same halts as
the force oracle, plus every sample within ±ORACLE_BAND of the torque target,
judged on the settled torque). The preload error of the torque-only stops is
still printed, as information: torque cannot reach the force oracle (on a
smoothly sliding joint T = μ_slip F r, not μ_stick F r).

Joints are classed by what the rig does near the target (true force within
±5 %): "stick-slip" when it sticks most of that time, else "smooth" (the
screw never stops: above the critical speed there is no stick phase, and no
plateau to choose). Plateau predictors compared: see
shared/stickslip/regression.py.
"""

from __future__ import annotations

import argparse
import copy
import math
import statistics
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from services.rig.physics import Measurement, TighteningPhysics
from shared.config import Program, RigSection
from shared.model import JointConstants
from shared.stickslip import PlateauMethod, PredictorCore, PredictorSettings
from tests.support.model_band_runs import drawn_program

SETTLE_SAMPLES = 300
LATENCY_SAMPLES = 1  # samples the motor still turns after the sample that triggered the stop
ORACLE_BAND = 0.03  # oracle halts tried at every sample with |F - F_target| ≤ this · F_target
CLASS_BAND = 0.05  # the class of a joint is what the rig does within this band of the target


@dataclass(frozen=True)
class Joint:
    constants: JointConstants
    program: Program
    target_force_n: float
    target_torque_nm: float
    seed: int


@dataclass(frozen=True)
class Oracle:
    reached_n: float
    reached_torque_nm: float  # the settled torque closest to the torque target
    smooth: bool  # no stick phase near the target
    step_n: float  # plateau step across the target (nan when smooth)
    plateaus_n: list[float]


@dataclass(frozen=True)
class Stop:
    reached_n: float
    reason: str
    slipping_at_trigger: bool  # the slip was under way when the stop was triggered
    reached_torque_nm: float = math.nan  # settled true torque


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
    program = drawn_program(speed, target, 3.0 * expected_s + 1.0)
    constants = JointConstants(k_e, k_s, r, mu_stick, mu_slip)
    return Joint(constants, program, target, target * r * mu_stick, seed)


def physics(joint: Joint) -> TighteningPhysics:
    return TighteningPhysics(joint.constants, joint.program, RigSection(), seed=joint.seed)


def finish(sim: TighteningPhysics) -> tuple[float, float]:
    """Halt and settle; the true (force N, torque Nm) the joint ends at."""
    sim.halt_motor()
    for _ in range(SETTLE_SAMPLES):
        if sim.settled:
            break
        sim.advance()
    return sim.true_force_n, sim.true_torque_nm


def max_samples(joint: Joint) -> int:
    return int(joint.program.max_time_s * 1000)


def oracle(joint: Joint) -> Oracle:
    """The best reachable end of the joint, and its class (see the module docstring)."""
    sim = physics(joint)
    target = joint.target_force_n
    target_torque = joint.target_torque_nm
    best = best_torque = math.inf
    was_slipping = True
    near = slipping_near = 0
    for _ in range(max_samples(joint)):
        sim.advance()
        force = sim.true_force_n
        if abs(force - target) <= CLASS_BAND * target:
            near += 1
            slipping_near += sim.slipping
        new_stick = not sim.slipping and was_slipping
        was_slipping = sim.slipping
        if (
            (new_stick and abs(force - target) <= 0.3 * target)
            or abs(force - target) <= ORACLE_BAND * target
            or abs(sim.true_torque_nm - target_torque) <= ORACLE_BAND * target_torque
        ):
            reached, torque = finish(copy.deepcopy(sim))
            if abs(reached - target) < abs(best - target):
                best = reached
            if abs(torque - target_torque) < abs(best_torque - target_torque):
                best_torque = torque
        if force > 1.5 * target:
            break
    plateaus = sim.plateau_forces_n
    above = [f for f in plateaus if f >= target]
    below = [f for f in plateaus if f < target]
    step = min(above) - max(below) if above and below else math.nan
    smooth = near == 0 or slipping_near > 0.5 * near
    return Oracle(best, best_torque, smooth, math.nan if smooth else step, plateaus)


def run(joint: Joint, stop: Callable[[Measurement], str | None]) -> Stop:
    """Tighten until ``stop`` names a reason; the motor halts LATENCY_SAMPLES later."""
    sim = physics(joint)
    for _ in range(max_samples(joint)):
        reason = stop(sim.advance())
        if reason is not None:
            slipping = sim.slipping
            for _ in range(LATENCY_SAMPLES):
                sim.advance()
            force, torque = finish(sim)
            return Stop(force, reason, slipping, torque)
    force, torque = finish(sim)
    return Stop(force, "none", False, torque)


def conventional(joint: Joint, torque_only: bool) -> Stop:
    def stop(m: Measurement) -> str | None:
        if torque_only:
            return "target" if m.torque_nm >= joint.target_torque_nm else None
        return "target" if m.force_n >= joint.target_force_n else None

    return run(joint, stop)


def predictor(joint: Joint, torque_only: bool, method: PlateauMethod, with_joint: bool) -> Stop:
    settings = PredictorSettings(
        target_force_n=None if torque_only else joint.target_force_n,
        target_torque_nm=joint.target_torque_nm if torque_only else None,
        has_force=not torque_only,
        motor_speed_rad_s=joint.program.motor_speed_rad_s,
        plateau_method=method,
        constants=joint.constants if with_joint else None,
    )
    core = PredictorCore(settings)

    def stop(m: Measurement) -> str | None:
        force = math.nan if torque_only else m.force_n
        core.update(m.time_s, m.torque_nm, force, m.angle_deg)
        return core.decision.reason if core.decision is not None else None

    return run(joint, stop)


def error(joint: Joint, reached_n: float) -> float:
    return abs(reached_n - joint.target_force_n) / joint.target_force_n


def torque_error(joint: Joint, reached_nm: float) -> float:
    return abs(reached_nm - joint.target_torque_nm) / joint.target_torque_nm


def stats(values: list[float]) -> str:
    if not values:
        return f"{'-':>7s} {'-':>7s} {'-':>7s}"
    ordered = sorted(values)
    p95 = ordered[min(len(ordered) - 1, int(0.95 * len(ordered)))]
    return (
        f"{100 * statistics.fmean(values):7.2f} {100 * statistics.median(values):7.2f} "
        f"{100 * p95:7.2f}"
    )


def outcome(plateaus: list[float], reached: float, best: float, stop: Stop) -> str:
    """Where a stop landed against the oracle's plateau: same, early (-k) or late (+k)."""
    if abs(reached - best) < 1e-6 * abs(best):
        return "same"
    index = min(range(len(plateaus)), key=lambda i: abs(plateaus[i] - reached))
    best_index = min(range(len(plateaus)), key=lambda i: abs(plateaus[i] - best))
    shift = index - best_index
    late = " (slip under way)" if stop.slipping_at_trigger else ""
    return f"{shift:+d} plateau{late}" if shift else "same plateau"


def print_table(
    title: str,
    rows: dict[str, list[float]],
    reasons: dict[str, dict[str, int]],
    oracle_name: str = "oracle",
) -> None:
    print(f"\n{title}")
    print(f"{'policy':34s} {'mean%':>7s} {'median%':>7s} {'p95%':>7s}  /oracle  /conv")
    if not rows.get(oracle_name):
        return
    oracle_mean = statistics.fmean(rows[oracle_name])
    for name, values in rows.items():
        conv = rows.get(f"conventional {'torque-only' if 'torque-only' in name else 'force'}")
        mean = statistics.fmean(values)
        ratio_conv = mean / statistics.fmean(conv) if conv else math.nan
        print(
            f"{name:34s} {stats(values)}  {mean / oracle_mean:6.2f}  {ratio_conv:5.2f}"
            f"  {reasons.get(name, '')}"
        )


def print_tables(
    rows: dict[str, dict[str, list[float]]],
    torque_rows: dict[str, dict[str, list[float]]],
    reasons: dict[str, dict[str, dict[str, int]]],
) -> None:
    """The force-metric tables, then the torque-metric tables of the torque-only policies."""
    print("\n=== |F_reached - F_target| / F_target (torque-only rows: preload, information)")
    for c, by_policy in rows.items():
        print_table(f"{c} ({len(by_policy.get('oracle', []))} joints)", by_policy, reasons[c])
    print("\n=== torque-only: |T_reached - T_target| / T_target, settled torque")
    for c, by_policy in torque_rows.items():
        count = len(by_policy.get("torque oracle", []))
        print_table(f"{c} ({count} joints)", by_policy, reasons[c], "torque oracle")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--joints", type=int, default=100)
    parser.add_argument("--seed", type=int, default=2018)
    parser.add_argument("--methods", default="poly2,linear,mean_step")
    parser.add_argument("--per-joint", action="store_true", help="one line per joint")
    parser.add_argument(
        "--no-joint", action="store_true", help="the predictor without the joint's model band"
    )
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    joints = [draw_joint(rng, args.seed * 1000 + i) for i in range(args.joints)]
    methods: list[PlateauMethod] = args.methods.split(",")
    classes = ("all", "stick-slip", "smooth")
    rows: dict[str, dict[str, list[float]]] = {c: {} for c in classes}
    torque_rows: dict[str, dict[str, list[float]]] = {c: {} for c in classes}
    reasons: dict[str, dict[str, dict[str, int]]] = {c: {} for c in classes}
    outcomes: dict[str, dict[str, int]] = {}
    started = time.process_time()
    wall = time.perf_counter()
    for number, joint in enumerate(joints):
        best = oracle(joint)
        joint_class = "smooth" if best.smooth else "stick-slip"
        results: dict[str, Stop] = {"oracle": Stop(best.reached_n, "", False)}
        for torque_only in (False, True):
            mode = "torque-only" if torque_only else "force"
            results[f"conventional {mode}"] = conventional(joint, torque_only)
            for method in methods:
                results[f"predictor {mode} {method}"] = predictor(
                    joint, torque_only, method, not args.no_joint
                )
        for c in ("all", joint_class):
            torque_rows[c].setdefault("torque oracle", []).append(
                torque_error(joint, best.reached_torque_nm)
            )
        for name, result in results.items():
            for c in ("all", joint_class):
                rows[c].setdefault(name, []).append(error(joint, result.reached_n))
                if "torque-only" in name:
                    torque_rows[c].setdefault(name, []).append(
                        torque_error(joint, result.reached_torque_nm)
                    )
                if name.startswith("predictor"):
                    counts = reasons[c].setdefault(name, {})
                    counts[result.reason] = counts.get(result.reason, 0) + 1
            if name.startswith("predictor") and not best.smooth:
                key = outcome(best.plateaus_n, result.reached_n, best.reached_n, result)
                tally = outcomes.setdefault(name, {})
                tally[key] = tally.get(key, 0) + 1
        if args.per_joint:
            k_e = joint.constants.k_e_nm_per_rad
            step = 100 * best.step_n / joint.target_force_n
            line = " ".join(f"{100 * error(joint, r.reached_n):5.2f}" for r in results.values())
            print(
                f"{number:3d} {joint_class:10s} step {step:5.2f}%"
                f" k_e {k_e:5.0f} w {joint.program.motor_speed_rad_s:4.2f} | {line}"
            )
    cpu_s = time.process_time() - started
    print(f"{len(joints)} joints, {cpu_s:.1f} s CPU, {time.perf_counter() - wall:.1f} s wall")
    print_tables(rows, torque_rows, reasons)
    print("\npredictor against the oracle on stick-slip joints:")
    for name, tally in outcomes.items():
        print(f"  {name:34s} {dict(sorted(tally.items()))}")


if __name__ == "__main__":
    main()
