"""How far eq. 71's model band is from stopping right joints, and how it catches wrong ones.

Run: ``.venv/bin/python tests/benchmarks/bench_band_margin.py [--joints N] [--seed S]``

The joints, programs and rig seeds of ``bench_predictor_accuracy.py``. Each
joint is tightened closed loop by the force-mode predictor (the accuracy
benchmark's stop latency and settling do not matter here) twice:

- configured with its own constants: every ``constant_out_of_band`` stop is a
  false stop. Printed: the count, the events the band judged, those it left
  out for lack of evidence (noise floor not settled, a period that was not
  one stick phase), and the largest share of its widened bound any median
  reached per constant (1.0 = a stop);
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

from shared.stickslip import PredictorCore, PredictorSettings, model_bands

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # run as a script: the repo root
from tests.benchmarks.bench_predictor_accuracy import (
    Joint,
    draw_joint,
    max_samples,
    physics,
)

WRONG_MU_SLIP_SHARE = 0.4  # the wrong joint's μ_slip as a share of its μ_stick


@dataclass(frozen=True)
class BandRun:
    reason: str
    events: int
    judged: int
    unsettled: int
    not_stick_periods: int
    nearest_edge: dict[int, float]


def tighten(joint: Joint, configured: Joint, evidence: bool) -> BandRun:
    """The predictor with ``configured``'s constants on ``joint``'s rig, until it stops.

    ``evidence`` False: every event judged, as before the evidence rules (comparison only).
    """
    core = PredictorCore(
        PredictorSettings(
            target_force_n=joint.target_force_n,
            target_torque_nm=None,
            has_force=True,
            motor_speed_rad_s=joint.program.motor_speed_rad_s,
            constants=configured.constants,
        )
    )
    if not evidence and core.model_bands is not None:
        core.model_bands._noise_settled = True
    sim = physics(joint)
    for _ in range(max_samples(joint)):
        m = sim.advance()
        core.update(m.time_s, m.torque_nm, m.force_n, m.angle_deg)
        if core.decision is not None:
            break
    bands = core.model_bands
    assert bands is not None
    reason = core.decision.reason if core.decision is not None else "none"
    return BandRun(
        reason,
        core.events,
        bands.judged,
        bands.unsettled,
        bands.not_stick_periods,
        dict(bands.nearest_edge),
    )


def wrong(joint: Joint) -> Joint:
    constants = replace(joint.constants, mu_slip=WRONG_MU_SLIP_SHARE * joint.constants.mu_stick)
    return replace(joint, constants=constants)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--joints", type=int, default=100)
    parser.add_argument("--seed", type=int, default=2018)
    parser.add_argument(
        "--without-evidence",
        action="store_true",
        help="judge every event (the rule before its evidence requirements), to compare",
    )
    args = parser.parse_args()
    evidence = not args.without_evidence
    if not evidence:
        model_bands.MIN_STICK_SHARE = -math.inf
    rng = np.random.default_rng(args.seed)
    joints = [draw_joint(rng, args.seed * 1000 + i) for i in range(args.joints)]
    right = [tighten(joint, joint, evidence) for joint in joints]
    false_stops = [i for i, run in enumerate(right) if run.reason == "constant_out_of_band"]
    print(f"seed {args.seed}, {len(joints)} joints, right constants:")
    print(f"  constant_out_of_band stops: {len(false_stops)} {false_stops}")
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
    wrong_runs = [tighten(joint, wrong(joint), evidence) for joint in joints]
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


if __name__ == "__main__":
    main()
