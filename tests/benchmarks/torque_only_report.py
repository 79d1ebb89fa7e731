"""What ``bench_torque_only.py`` prints: a table per family, the worst joints, a JSON line each.

Per family, mean / p95 / signed worst of |T_reached − T*| / T* for every torque
stop (with the preload it leaves, which a torque-only station cannot see) and
of |F_reached − F*| / F* for the force stops; the joints where boltwatch's
torque-only stops end more than 1 % of T* worse than conventional; the drops
lost; the cycle time (start to the run's end) of each policy; the worst
joints with the decision that ended them. Last, one JSON object per line for
each family and policy (``{"family": .., "policy": .., "mean_pct": ..}``) that
a script can read.
"""

from __future__ import annotations

import json
import math
import statistics
from collections.abc import Callable, Iterator
from dataclasses import dataclass

from tests.benchmarks.torque_only_joints import Joint

WORSE_THAN_CONVENTIONAL = 0.01
#: the rows of torque stops, and which End of a JointResult each reads
TORQUE_POLICIES = (
    "conventional torque",
    "boltwatch torque-only",
    "boltwatch torque-only staged",
)
FORCE_POLICIES = ("conventional force", "boltwatch force", "boltwatch force staged")


@dataclass(frozen=True)
class End:
    """Where a stop left the joint: settled true torque and preload, and why it stopped."""

    torque_nm: float
    force_n: float
    reason: str = ""
    detail: str = ""
    decided_nm: float = math.nan  # measured torque at the deciding sample
    cycle_samples: int = 0  # start to settled (the controller's end of the run)
    pulses: int = 0  # staged: pulses back to the target


@dataclass(frozen=True)
class JointResult:
    joint: Joint
    oracle_torque: End
    oracle_force: End
    stops: dict[str, End]
    drops_pct: list[float]  # true slip drops near the target, % of T* (unstopped run)


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


@dataclass(frozen=True)
class Figures:
    """mean and p95 of |e|, the signed worst and the most below target, in %."""

    mean_pct: float
    p95_pct: float
    worst_pct: float
    lowest_pct: float

    @classmethod
    def of(cls, errors: list[float]) -> Figures:
        magnitudes = sorted(abs(e) for e in errors)
        p95 = magnitudes[min(len(magnitudes) - 1, math.ceil(0.95 * len(magnitudes)) - 1)]
        return cls(
            100 * statistics.fmean(magnitudes),
            100 * p95,
            100 * max(errors, key=abs),
            100 * min(errors),
        )

    def __str__(self) -> str:
        return f"{self.mean_pct:6.2f} {self.p95_pct:6.2f} {self.worst_pct:+7.2f}"


def print_family(family: str, role: str, results: list[JointResult], worst: int) -> None:
    print(f"\n{family} ({role}, {len(results)} joints)   mean% / p95% / worst% (signed)")
    header = f"{'stop':30s} {'torque |T-T*|/T*':>22s}   {'preload |F-F*|/F*':>22s}  cycle ms"
    print(header)
    rows: list[tuple[str, Callable[[JointResult], End]]] = [("oracle", lambda r: r.oracle_torque)]
    rows += [(name, _stop(name)) for name in TORQUE_POLICIES]
    for name, pick in rows:
        torque = Figures.of([torque_error(r, pick(r)) for r in results])
        preload = Figures.of([force_error(r, pick(r)) for r in results])
        cycle = "" if name == "oracle" else f"{_median_cycle(results, pick):8.0f}"
        print(f"{name:30s} {torque!s:>22s}   {preload!s:>22s}  {cycle}")
    force_rows: list[tuple[str, Callable[[JointResult], End]]] = [
        ("oracle (preload)", lambda r: r.oracle_force)
    ]
    force_rows += [(name, _stop(name)) for name in FORCE_POLICIES]
    for name, pick in force_rows:
        preload = Figures.of([force_error(r, pick(r)) for r in results])
        cycle = "" if name.startswith("oracle") else f"{_median_cycle(results, pick):8.0f}"
        print(f"{name:30s} {'':>22s}   {preload!s:>22s}  {cycle}")
    oracle_mean = statistics.fmean(abs(torque_error(r, r.oracle_torque)) for r in results)
    conv = [abs(torque_error(r, r.stops["conventional torque"])) for r in results]
    for name in TORQUE_POLICIES[1:]:
        bw = [abs(torque_error(r, r.stops[name])) for r in results]
        worse = sum(b - c > WORSE_THAN_CONVENTIONAL for b, c in zip(bw, conv, strict=True))
        print(
            f"{name}: {statistics.fmean(bw) / max(oracle_mean, 1e-12):.1f}x oracle, "
            f"{statistics.fmean(bw) / statistics.fmean(conv):.2f}x conventional; "
            f"joints > 1 % of T* worse than conventional: {worse}"
        )
    stick = [r for r in results if r.drops_pct]
    smooth = [r for r in results if not r.drops_pct]
    for name in TORQUE_POLICIES:
        lost = sum(lost_drop(r, r.stops[name]) for r in results)
        by_class = " / ".join(
            f"{statistics.fmean(abs(torque_error(r, r.stops[name])) for r in rs) * 100:.2f}"
            if rs
            else "-"
            for rs in (stick, smooth)
        )
        print(f"  {name}: mean % stick-slip / smooth near T* {by_class}; drops lost {lost}")
    print(f"  ({len(stick)} joints stick and slip near T*, {len(smooth)} slide smoothly there)")
    staged = "boltwatch torque-only staged"
    pulsed = sum(r.stops[staged].pulses > 0 for r in results)
    ratio = statistics.median(
        r.stops[staged].cycle_samples / r.stops["boltwatch torque-only"].cycle_samples
        for r in results
    )
    print(
        f"  staged: {pulsed} of {len(results)} runs took a pulse; cycle time against "
        f"stop-only, median of the ratios: {ratio:.3f}"
    )
    for name in ("boltwatch torque-only", staged):
        ranked = sorted(results, key=lambda r: -abs(torque_error(r, r.stops[name])))
        print(f"  worst of {name}:")
        for r in ranked[:worst]:
            print_joint(r, name)


def _stop(name: str) -> Callable[[JointResult], End]:
    return lambda r: r.stops[name]


def _median_cycle(results: list[JointResult], pick: Callable[[JointResult], End]) -> float:
    return float(statistics.median(pick(r).cycle_samples for r in results))


def print_joint(r: JointResult, name: str) -> None:
    j = r.joint
    end = r.stops[name]
    conv = r.stops["conventional torque"]
    drops = f"{statistics.median(r.drops_pct):.1f}" if r.drops_pct else "-"
    scatter = j.rig.mu_stick_scatter
    print(
        f"    #{j.number:<3d} drop {100 * j.drop_share:4.1f}% (true {drops}%) "
        f"scatter {100 * scatter:3.1f}% ramp {j.ramp_samples_per_pct:4.1f} "
        f"smp/% | oracle {100 * torque_error(r, r.oracle_torque):+6.2f} "
        f"conv {100 * torque_error(r, conv):+6.2f} this {100 * torque_error(r, end):+6.2f} "
        f"[{end.reason}: {end.detail}]"
    )


def json_lines(family: str, results: list[JointResult]) -> Iterator[str]:
    """One JSON object per policy of ``family``: its figures, cycle time, pulses, lost drops."""
    for name in ("oracle", *TORQUE_POLICIES, "oracle (preload)", *FORCE_POLICIES):
        force = name in FORCE_POLICIES or name == "oracle (preload)"
        ends = [
            r.oracle_torque
            if name == "oracle"
            else r.oracle_force
            if name == "oracle (preload)"
            else r.stops[name]
            for r in results
        ]
        errors = [
            force_error(r, e) if force else torque_error(r, e)
            for r, e in zip(results, ends, strict=True)
        ]
        figures = Figures.of(errors)
        record: dict[str, object] = {
            "family": family,
            "policy": name,
            "quantity": "preload" if force else "torque",
            "joints": len(results),
            "mean_pct": round(figures.mean_pct, 4),
            "p95_pct": round(figures.p95_pct, 4),
            "worst_pct": round(figures.worst_pct, 4),
            "lowest_pct": round(figures.lowest_pct, 4),
        }
        if not name.startswith("oracle"):
            cycles = [e.cycle_samples for e in ends]
            record["cycle_median_ms"] = statistics.median(cycles)
            record["pulsed_runs"] = sum(e.pulses > 0 for e in ends)
            if not force:
                record["drops_lost"] = sum(
                    lost_drop(r, e) for r, e in zip(results, ends, strict=True)
                )
        yield json.dumps(record)
