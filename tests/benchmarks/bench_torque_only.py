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
import math
import statistics
import sys
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from services.rig.physics import Measurement, TighteningPhysics
from shared.stickslip import PredictorCore, PredictorSettings
from tests.benchmarks.torque_only_joints import FAMILIES, Joint, family_joints

SETTLE_SAMPLES = 300
LATENCY_SAMPLES = 1
TORQUE_BAND = 0.05  # oracle halts at every sample with |T - T*| ≤ this · T*
FORCE_BAND = 0.03  # ... and with |F - F*| ≤ this · F*
STICK_BAND = 0.3  # ... and at every new stick phase with |F - F*| ≤ this · F*
WORSE_THAN_CONVENTIONAL = 0.01


@dataclass(frozen=True)
class End:
    """Where a stop left the joint: settled true torque and preload, and why it stopped."""

    torque_nm: float
    force_n: float
    reason: str = ""
    detail: str = ""
    decided_nm: float = math.nan  # measured torque at the deciding sample


@dataclass(frozen=True)
class JointResult:
    joint: Joint
    oracle_torque: End
    oracle_force: End
    stops: dict[str, End]
    drops_pct: list[float]  # true slip drops near the target, % of T* (unstopped run)


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
    for _ in range(samples(joint)):
        m = sim.advance()
        said = decide(m)
        if said is not None:
            for _ in range(LATENCY_SAMPLES):
                sim.advance()
            return End(*settle(sim), reason=said[0], detail=said[1], decided_nm=m.torque_nm)
    return End(*settle(sim), reason="none")


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


def measure(joint: Joint) -> JointResult:
    best_t, best_f, drops = oracle(joint)
    stops = {
        "conventional torque": conventional(joint, torque_only=True),
        "boltwatch torque-only": boltwatch(joint, torque_only=True),
        "conventional force": conventional(joint, torque_only=False),
        "boltwatch force": boltwatch(joint, torque_only=False),
    }
    return JointResult(joint, best_t, best_f, stops, drops)


def torque_error(r: JointResult, end: End) -> float:
    """Signed (T_reached − T*) / T*."""
    return (end.torque_nm - r.joint.target_torque_nm) / r.joint.target_torque_nm


def force_error(r: JointResult, end: End) -> float:
    """Signed (F_reached − F*) / F*."""
    return (end.force_n - r.joint.target_force_n) / r.joint.target_force_n


def lost_drop(r: JointResult, end: End) -> bool:
    """The stop ended a slip drop low: more than half a drop (and 1 %) under T*."""
    drop = statistics.median(r.drops_pct) / 100.0 if r.drops_pct else r.joint.drop_share
    return torque_error(r, end) < -max(WORSE_THAN_CONVENTIONAL, 0.5 * drop)


def summary(errors: list[float]) -> str:
    """mean / p95 of |e| and the signed worst, in %."""
    magnitudes = sorted(abs(e) for e in errors)
    p95 = magnitudes[min(len(magnitudes) - 1, math.ceil(0.95 * len(magnitudes)) - 1)]
    worst = max(errors, key=abs)
    return f"{100 * statistics.fmean(magnitudes):6.2f} {100 * p95:6.2f} {100 * worst:+7.2f}"


def print_family(family: str, results: list[JointResult], worst: int) -> None:
    role = FAMILIES[family][0]
    print(f"\n{family} ({role}, {len(results)} joints)   mean% / p95% / worst% (signed)")
    header = f"{'stop':24s} {'torque |T-T*|/T*':>22s}   {'preload |F-F*|/F*':>22s}"
    print(header)
    rows: list[tuple[str, Callable[[JointResult], End]]] = [
        ("oracle", lambda r: r.oracle_torque),
        ("conventional torque", lambda r: r.stops["conventional torque"]),
        ("boltwatch torque-only", lambda r: r.stops["boltwatch torque-only"]),
    ]
    for name, pick in rows:
        torque = summary([torque_error(r, pick(r)) for r in results])
        preload = summary([force_error(r, pick(r)) for r in results])
        print(f"{name:24s} {torque:>22s}   {preload:>22s}")
    for name, pick in (
        ("oracle (preload)", lambda r: r.oracle_force),
        ("conventional force", lambda r: r.stops["conventional force"]),
        ("boltwatch force", lambda r: r.stops["boltwatch force"]),
    ):
        print(f"{name:24s} {'':>22s}   {summary([force_error(r, pick(r)) for r in results]):>22s}")
    oracle_mean = statistics.fmean(abs(torque_error(r, r.oracle_torque)) for r in results)
    bw = [abs(torque_error(r, r.stops["boltwatch torque-only"])) for r in results]
    conv = [abs(torque_error(r, r.stops["conventional torque"])) for r in results]
    worse = sum(b - c > WORSE_THAN_CONVENTIONAL for b, c in zip(bw, conv, strict=True))
    worse_preload = sum(
        abs(force_error(r, r.stops["boltwatch torque-only"]))
        - abs(force_error(r, r.stops["conventional torque"]))
        > WORSE_THAN_CONVENTIONAL
        for r in results
    )
    print(
        f"torque-only: {statistics.fmean(bw) / max(oracle_mean, 1e-12):.1f}x oracle, "
        f"{statistics.fmean(bw) / statistics.fmean(conv):.2f}x conventional; "
        f"joints > 1 % of T* worse than conventional: {worse}; "
        f"preload > 1 % of F* worse: {worse_preload}"
    )
    stick = [r for r in results if r.drops_pct]
    smooth = [r for r in results if not r.drops_pct]
    for name in ("conventional torque", "boltwatch torque-only"):
        lost = sum(lost_drop(r, r.stops[name]) for r in results)
        by_class = " / ".join(
            f"{statistics.fmean(abs(torque_error(r, r.stops[name])) for r in rs) * 100:.2f}"
            if rs
            else "-"
            for rs in (stick, smooth)
        )
        print(f"  {name}: mean % stick-slip / smooth near T* {by_class}; drops lost {lost}")
    print(f"  ({len(stick)} joints stick and slip near T*, {len(smooth)} slide smoothly there)")
    ranked = sorted(results, key=lambda r: -abs(torque_error(r, r.stops["boltwatch torque-only"])))
    for r in ranked[:worst]:
        print_joint(r)


def print_joint(r: JointResult) -> None:
    j = r.joint
    bw = r.stops["boltwatch torque-only"]
    conv = r.stops["conventional torque"]
    drops = f"{statistics.median(r.drops_pct):.1f}" if r.drops_pct else "-"
    print(
        f"  #{j.number:<3d} drop {100 * j.drop_share:4.1f}% (true {drops}%) "
        f"scatter {100 * j.rig.mu_stick_scatter:3.1f}% ramp {j.ramp_samples_per_pct:4.1f} "
        f"smp/% | oracle {100 * torque_error(r, r.oracle_torque):+6.2f} "
        f"conv {100 * torque_error(r, conv):+6.2f} bw {100 * torque_error(r, bw):+6.2f} "
        f"[{bw.reason}: {bw.detail}]"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--joints", type=int, default=40, help="joints per family")
    parser.add_argument("--families", default=",".join(FAMILIES))
    parser.add_argument("--jobs", type=int, default=1, help="worker processes")
    parser.add_argument("--worst", type=int, default=3, help="worst joints listed per family")
    args = parser.parse_args()
    families = args.families.split(",")
    joints = [j for f in families for j in family_joints(f, args.joints)]
    wall = time.perf_counter()
    if args.jobs > 1:
        with ProcessPoolExecutor(args.jobs) as pool:
            results = list(pool.map(measure, joints, chunksize=2))
    else:
        results = [measure(j) for j in joints]
    print(f"{len(joints)} joints in {time.perf_counter() - wall:.0f} s wall, {args.jobs} job(s)")
    for family in families:
        print_family(family, [r for r in results if r.joint.family == family], args.worst)


if __name__ == "__main__":
    main()
