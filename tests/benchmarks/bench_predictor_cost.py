"""CPU time per sample of the predictor core (not a test).

Run: ``.venv/bin/python tests/benchmarks/bench_predictor_cost.py [--runs N]``

Records long rig runs first (so the physics is not timed), then feeds each
to a fresh core and reports the median over runs of CPU time per sample.
Goal: < 5 µs per sample (the 1 kHz budget is 1000 µs).

Three modes on the same recordings: force (target out of reach, the
streaming cost), torque-only with the target out of reach, and torque-only
with the target at the run's highest torque, so that the torque halt plan
(a grid search per event near the target, shared/stickslip/halt_planner.py)
runs on the last stretch of every run; a latched decision ends planning, so
the target is crossed only at the very end.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

from services.rig.physics import TighteningPhysics
from shared.config import Program, RigSection
from shared.model import JointConstants
from shared.stickslip import PredictorCore, PredictorSettings

#: a target no run reaches (an infinite one is refused, and would decide at once: every
#: plateau is as far from it as the next)
OUT_OF_REACH = 1e12


def record(seed: int, samples: int) -> list[tuple[float, float, float, float]]:
    program = Program(
        id=1,
        name="cost",
        target_force_n=1e9,
        motor_speed_rad_s=0.3,
        start_force_n=10_000.0,
        max_torque_nm=1e6,
        max_angle_deg=1e6,
        max_time_s=1e3,
    )
    constants = JointConstants(600.0, 20_000.0, 0.011, 0.36, 0.34)
    sim = TighteningPhysics(constants, program, RigSection(), seed=seed)
    rows = []
    for _ in range(samples):
        m = sim.advance()
        rows.append((m.time_s, m.torque_nm, m.force_n, m.angle_deg))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--samples", type=int, default=20_000)
    args = parser.parse_args()
    recordings = [record(seed, args.samples) for seed in range(args.runs)]
    modes = ("force", "torque-only, target out of reach", "torque-only, target at the end")
    for mode in modes:
        per_sample_us = []
        events = planned = 0
        for recording in recordings:
            rows = recording
            if mode == "force":
                settings = PredictorSettings(target_force_n=OUT_OF_REACH)
            else:
                top = max(row[1] for row in recording) if mode.endswith("end") else OUT_OF_REACH
                settings = PredictorSettings(target_torque_nm=top, has_force=False)
                rows = [(t, torque, math.nan, angle) for t, torque, _, angle in recording]
            core = PredictorCore(settings)
            update = core.update
            started = time.process_time()
            for row in rows:
                update(*row)
            per_sample_us.append((time.process_time() - started) / len(rows) * 1e6)
            events += core.events
            planner = core.halt_planner
            planned += planner.planned if planner is not None else 0
        print(
            f"{mode}: {args.runs} runs x {args.samples} samples, {events} events, "
            f"{planned} halt plans: CPU per sample median "
            f"{statistics.median(per_sample_us):.2f} µs "
            f"(min {min(per_sample_us):.2f}, max {max(per_sample_us):.2f})"
        )


if __name__ == "__main__":
    main()
