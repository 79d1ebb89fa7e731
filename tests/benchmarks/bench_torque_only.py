"""Torque-only and force stops on joints drawn wider than the tuned set, against the oracle.

Run on demand (not collected by pytest)::

    .venv/bin/python tests/benchmarks/bench_torque_only.py [--joints 40]
        [--families tune-a,tune-b,judge-a,judge-b,judge-c,paper] [--jobs 2] [--worst 5]

The joints and their families: ``torque_only_joints.py`` (slip drops 2-25 %
of the target, μ_stick scatter 0-5 % per stick phase, stick ramps 1-20
samples per percent, sensor noise, and the paper's joints). Families named
"tune-*" are the ones a rule may be tuned on; the others judge it.

Per joint, each stop on the same joint (same seed: same friction draws and
noise), with the rig's pure physics and the predictor's pure core (the code
the live station runs), the motor halting one sample after the deciding
sample, and the figure taken once the motor has halted and any slip settled:

- **oracle**: the joint run again and halted at every sample whose true
  torque is within ±5 % of T* or true preload within ±3 % of F*, and at every
  new stick phase within ±30 % of F*, each settled; the closest end is kept,
  on torque and on preload separately (the best any stop-only controller
  can do);
- **conventional**: halt when the measured torque (force mode: force) first
  reaches the target;
- **boltwatch torque-only**: the core with a torque target and no force;
- **boltwatch force**: the core with a force target and the force sensor.

Both boltwatch modes get the joint's constants, as a station gets its joint
file. Printed per family: mean / p95 / worst of |T_reached − T*| / T* for the
torque-only stops (with the preload they leave beside it, which a
torque-only station cannot see), |F_reached − F*| / F* for force mode, the
number of joints where boltwatch's torque-only stop is more than 1 % of T*
worse than conventional, and the worst joints with the decision that ended
them (``--worst``).
"""

from __future__ import annotations

import argparse
import copy
import functools
import math
import sys
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from services.rig.physics import Measurement, TighteningPhysics
from shared.stickslip import PredictorCore, PredictorSettings
from tests.benchmarks.torque_only_joints import FAMILIES, Joint, family_joints
from tests.benchmarks.torque_only_report import End, JointResult, json_lines, print_family
from tests.support.staged_runs import SETTLE_TIME_S, run_staged, staged_program

SETTLE_SAMPLES = 300
LATENCY_SAMPLES = 1
TORQUE_BAND = 0.05  # oracle halts at every sample with |T - T*| ≤ this · T*
FORCE_BAND = 0.03  # ... and with |F - F*| ≤ this · F*
STICK_BAND = 0.3  # ... and at every new stick phase with |F - F*| ≤ this · F*
FINAL_SHARE = 0.1  # a staged program's final speed, as a share of its rundown speed


def physics(joint: Joint) -> TighteningPhysics:
    return TighteningPhysics(joint.constants, joint.program, joint.rig, seed=joint.seed)


def settle(sim: TighteningPhysics) -> tuple[float, float]:
    """Halt the motor and let any slip finish; the true (torque Nm, force N) left."""
    sim.halt_motor()
    for _ in range(SETTLE_SAMPLES):
        if sim.settled:
            break
        sim.advance()
    return sim.true_torque_nm, sim.true_force_n


def settled_end(sim: TighteningPhysics, halted_at: int, **said: str | float) -> End:
    """The End of a run halted after ``halted_at`` samples; its cycle as a controller ends it
    (the slip finished and its settle time passed)."""
    sim.halt_motor()
    waited = 0
    while waited < SETTLE_SAMPLES and not sim.settled:
        sim.advance()
        waited += 1
    cycle = halted_at + max(waited, round(SETTLE_TIME_S * 1000))
    return End(sim.true_torque_nm, sim.true_force_n, cycle_samples=cycle, **said)  # type: ignore[arg-type]


def samples(joint: Joint) -> int:
    return int(joint.program.max_time_s * 1000)


def oracle(joint: Joint) -> tuple[End, End, list[float]]:
    """The closest settled torque and preload any halt reaches; the slip drops near T*."""
    sim = physics(joint)
    t_star, f_star = joint.target_torque_nm, joint.target_force_n
    best_t = best_f = End(math.inf, math.inf)
    was_slipping = False
    peak = math.nan
    drops: list[float] = []
    for _ in range(samples(joint)):
        before = sim.true_torque_nm
        sim.advance()
        torque, force = sim.true_torque_nm, sim.true_force_n
        if sim.slipping and not was_slipping:
            peak = before
        new_stick = was_slipping and not sim.slipping
        if new_stick and abs(peak - t_star) <= 0.3 * t_star:
            drops.append(100.0 * (peak - torque) / t_star)
        was_slipping = sim.slipping
        if (
            abs(torque - t_star) <= TORQUE_BAND * t_star
            or abs(force - f_star) <= FORCE_BAND * f_star
            or (new_stick and abs(force - f_star) <= STICK_BAND * f_star)
        ):
            end = End(*settle(copy.deepcopy(sim)), reason="oracle")
            if abs(end.torque_nm - t_star) < abs(best_t.torque_nm - t_star):
                best_t = end
            if abs(end.force_n - f_star) < abs(best_f.force_n - f_star):
                best_f = end
        if force > 1.5 * f_star or torque > 1.5 * t_star:
            break
    return best_t, best_f, drops


def run(joint: Joint, decide: Callable[[Measurement], tuple[str, str] | None]) -> End:
    """Tighten until ``decide`` gives (reason, detail); the motor halts LATENCY_SAMPLES later."""
    sim = physics(joint)
    for n in range(1, samples(joint) + 1):
        m = sim.advance()
        said = decide(m)
        if said is not None:
            for _ in range(LATENCY_SAMPLES):
                sim.advance()
            halted = n + LATENCY_SAMPLES
            return settled_end(sim, halted, reason=said[0], detail=said[1], decided_nm=m.torque_nm)
    return settled_end(sim, samples(joint), reason="none")


def conventional(joint: Joint, torque_only: bool) -> End:
    def decide(m: Measurement) -> tuple[str, str] | None:
        if torque_only:
            return ("target", "") if m.torque_nm >= joint.target_torque_nm else None
        return ("target", "") if m.force_n >= joint.target_force_n else None

    return run(joint, decide)


def boltwatch(joint: Joint, torque_only: bool) -> End:
    settings = PredictorSettings(
        target_force_n=None if torque_only else joint.target_force_n,
        target_torque_nm=joint.target_torque_nm if torque_only else None,
        has_force=not torque_only,
        motor_speed_rad_s=joint.program.motor_speed_rad_s,
        constants=joint.constants,
    )
    core = PredictorCore(settings)

    def decide(m: Measurement) -> tuple[str, str] | None:
        core.update(m.time_s, m.torque_nm, math.nan if torque_only else m.force_n, m.angle_deg)
        d = core.decision
        return None if d is None else (d.reason, d.detail)

    return run(joint, decide)


def staged(joint: Joint, torque_only: bool, final_share: float) -> End:
    """boltwatch with the program's final stage (``staged_runs.run_staged``)."""
    program = staged_program(
        joint.program,
        final_share,
        joint.target_torque_nm,
        None if torque_only else joint.target_force_n,
    )
    end = run_staged(joint.constants, program, joint.rig, joint.seed, torque_only, LATENCY_SAMPLES)
    return End(
        end.torque_nm,
        end.force_n,
        reason=end.reason,
        detail=f"{' '.join(end.commands)}: {end.detail}",
        cycle_samples=end.cycle_samples,
        pulses=end.pulses,
    )


def measure(joint: Joint, final_share: float = FINAL_SHARE) -> JointResult:
    best_t, best_f, drops = oracle(joint)
    stops = {
        "conventional torque": conventional(joint, torque_only=True),
        "boltwatch torque-only": boltwatch(joint, torque_only=True),
        "boltwatch torque-only staged": staged(joint, True, final_share),
        "conventional force": conventional(joint, torque_only=False),
        "boltwatch force": boltwatch(joint, torque_only=False),
        "boltwatch force staged": staged(joint, False, final_share),
    }
    return JointResult(joint, best_t, best_f, stops, drops)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--joints", type=int, default=40, help="joints per family")
    parser.add_argument("--families", default=",".join(FAMILIES))
    parser.add_argument("--jobs", type=int, default=1, help="worker processes")
    parser.add_argument("--worst", type=int, default=3, help="worst joints listed per family")
    parser.add_argument(
        "--final-share",
        type=float,
        default=FINAL_SHARE,
        help="a staged program's final speed as a share of its rundown speed",
    )
    args = parser.parse_args()
    families = args.families.split(",")
    joints = [j for f in families for j in family_joints(f, args.joints)]
    wall = time.perf_counter()
    work = functools.partial(measure, final_share=args.final_share)
    if args.jobs > 1:
        with ProcessPoolExecutor(args.jobs) as pool:
            results = list(pool.map(work, joints, chunksize=2))
    else:
        results = [work(j) for j in joints]
    print(f"{len(joints)} joints in {time.perf_counter() - wall:.0f} s wall, {args.jobs} job(s)")
    for family in families:
        of_family = [r for r in results if r.joint.family == family]
        print_family(family, FAMILIES[family][0], of_family, args.worst)
    print()
    for family in families:
        for line in json_lines(family, [r for r in results if r.joint.family == family]):
            print(line)


if __name__ == "__main__":
    main()
