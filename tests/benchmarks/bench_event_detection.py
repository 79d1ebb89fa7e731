"""Recall of the core's slip detection against the rig's true slips (not a test).

Run: ``.venv/bin/python tests/benchmarks/bench_event_detection.py [--joints N] [--windows 5,3]``

The joints are those of bench_predictor_accuracy.py (same draw, same seed).
Each joint is tightened without a stop (to 1.5 × its target force or its
time limit) while the core, with no target, watches the torque. A true slip
is a stick phase breaking in the rig (its ``slip_count`` steps); it is found
when the core reports an event whose peak sample is within MATCH_SAMPLES of
the last sample before the slip. Each event is matched to at most one slip;
events matched to none are false events.

Per true slip the benchmark keeps its frequency (1 / time since the slip
before), its true drop (true torque at the break minus the lowest true
torque sampled before the next stick phase) and the samples of its stick
phase, and classes each miss:

- hidden by ramp: the drop is no larger than the stick ramp's rise over the
  rest of the window's span, (window - 2) · rise per sample: the
  inclination sum telescopes to T_newest - T_oldest (eq. 46), which then
  never turns negative, so no maximum is ever flagged;
- below floor: the sampled drop is under the tracker's noise floor at the time;
- other:        neither (e.g. a slip merged into its neighbour by the
  pairing of flips).

Two more columns: "≤ noise" counts the misses whose true drop is within the
floor the tracker would have on noise alone (NOISE_FACTOR · 1.65 σ of the
rig's torque noise), i.e. slips no detector can tell from noise without
false events; "floor Nm" is the median floor the tracker had at the slips of
the band, which stick-slip itself lifts when its kinks are most samples.

Recall is printed per frequency band, which is what the docstring of
shared/stickslip/settings.py quotes.
"""

from __future__ import annotations

import argparse
import itertools
import math
import statistics
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from shared.config import RigSection
from shared.stickslip import NOISE_FACTOR, EventFigures, PredictorCore, PredictorSettings

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # run as a script: the repo root
from tests.benchmarks.bench_predictor_accuracy import (
    Joint,
    draw_joint,
    max_samples,
    physics,
)

MATCH_SAMPLES = 5
BANDS_HZ = (0.0, 50.0, 100.0, 150.0, 200.0, 300.0, 1e9)


@dataclass
class TrueSlip:
    index: int  # the last sample before the break
    frequency_hz: float  # 1 / time since the previous break (nan for the first)
    drop_nm: float  # true torque at the break minus the lowest true torque sampled after
    stick_samples: int  # samples of the stick phase that ended at this break
    rise_nm: float  # true torque rise per sample of that stick phase
    floor_nm: float  # the tracker's noise floor when the slip happened
    found: bool = False


def observe(window: int, joint: Joint) -> tuple[list[TrueSlip], int, int]:
    """(true slips, events, false events) of one joint for one window size."""
    sim = physics(joint)
    core = PredictorCore(PredictorSettings(window_samples=window, has_force=False))
    slips: list[TrueSlip] = []
    peaks: list[int] = []
    last_break_s = math.nan
    stick_start = 0
    stick_torque = sim.true_torque_nm
    slipping = False
    target = joint.target_force_n
    for index in range(max_samples(joint)):
        before = sim.slip_count
        torque_before = sim.true_torque_nm
        m = sim.advance()
        if sim.slip_count > before:
            # a break in this sample: the sample before is the peak of its stick phase
            period = sim.time_s - last_break_s
            slips.append(
                TrueSlip(
                    index - 1,
                    1.0 / period if period > 0 else math.nan,
                    0.0,
                    index - stick_start,
                    (torque_before - stick_torque) / max(1, index - stick_start),
                    core._tracker.min_drop_nm(torque_before),
                )
            )
            slips[-1].drop_nm = torque_before - sim.true_torque_nm
            last_break_s = sim.time_s
        elif sim.slipping and slips:
            slips[-1].drop_nm = max(slips[-1].drop_nm, torque_before - sim.true_torque_nm)
        if slipping and not sim.slipping:
            stick_start = index
            stick_torque = sim.true_torque_nm
        slipping = sim.slipping
        for output in core.update(m.time_s, m.torque_nm, math.nan, m.angle_deg):
            if isinstance(output, EventFigures):
                peaks.append(round(output.time_s * 1000.0) - 1)
        if sim.true_force_n > 1.5 * target:
            break
    return slips, len(peaks), match(slips, peaks)


def match(slips: list[TrueSlip], peaks: list[int]) -> int:
    """Mark the slips found by the events' peaks; the number of false events."""
    false_events = 0
    for peak in peaks:
        near = [s for s in slips if not s.found and abs(s.index - peak) <= MATCH_SAMPLES]
        if near:
            min(near, key=lambda s: abs(s.index - peak)).found = True
        else:
            false_events += 1
    return false_events


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--joints", type=int, default=100)
    parser.add_argument("--seed", type=int, default=2018)
    parser.add_argument("--windows", default="5,3")
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    joints = [draw_joint(rng, args.seed * 1000 + i) for i in range(args.joints)]
    for window in (int(w) for w in args.windows.split(",")):
        slips: list[TrueSlip] = []
        events = false_events = 0
        for joint in joints:
            found, count, false = observe(window, joint)
            slips += found
            events += count
            false_events += false
        report(window, slips, events, false_events)


def report(window: int, slips: list[TrueSlip], events: int, false_events: int) -> None:
    frequencies = sorted(s.frequency_hz for s in slips if math.isfinite(s.frequency_hz))
    found = sum(s.found for s in slips)
    print(
        f"\nwindow n = {window}: {len(slips)} true slips, {events} events, "
        f"recall {100 * found / len(slips):.1f} %, {false_events} false events"
    )
    if frequencies:
        q = [frequencies[int(p * (len(frequencies) - 1))] for p in (0.5, 0.95, 1.0)]
        print(f"true slip frequency: median {q[0]:.0f} Hz, p95 {q[1]:.0f} Hz, max {q[2]:.0f} Hz")
    print(
        f"{'band Hz':>12s} {'slips':>7s} {'recall%':>8s} {'hidden by ramp':>15s} "
        f"{'below floor':>12s} {'other':>7s} {'≤ noise':>8s} {'floor Nm':>9s}"
    )
    noise_floor_nm = NOISE_FACTOR * 1.65 * RigSection().torque_noise_nm
    for low, high in itertools.pairwise(BANDS_HZ):
        band = [s for s in slips if low <= s.frequency_hz < high]
        if not band:
            continue
        missed = [s for s in band if not s.found]
        hidden = sum(s.drop_nm <= (window - 2) * s.rise_nm for s in missed)
        below = sum(s.floor_nm >= s.drop_nm > (window - 2) * s.rise_nm for s in missed)
        name = f"{low:.0f}-{high:.0f}" if high < 1e8 else f"≥ {low:.0f}"
        print(
            f"{name:>12s} {len(band):7d} {100 * (len(band) - len(missed)) / len(band):8.1f} "
            f"{hidden:15d} {below:12d} {len(missed) - hidden - below:7d} "
            f"{sum(s.drop_nm <= noise_floor_nm for s in missed):8d} "
            f"{statistics.median(s.floor_nm for s in band):9.2f}"
        )


if __name__ == "__main__":
    main()
