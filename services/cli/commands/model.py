"""``boltwatch model``: the paper's analytical model for one joint, and a check of the rig.

    boltwatch model [--joint FILE] [--speed RAD_S] [--target-force N]
                    [--target-torque NM] [--json] [--plot OUT.png]
    boltwatch model --validate [--out report.png] [--json]

The report: stiffnesses, γ's, the stick-slip frequency, force-step and
torque-drop bands at the target, time to target, K1-K3 bands, the
torque-preload relation and the extension's natural frequency
(:mod:`shared.model.report`). ``--plot`` draws the bounds over time and over
the extension's length and diameter (the paper's Figures 4, 6, 7, 13-15).
``--validate`` tightens a grid of joints with the simulated rig and checks
what it measures against the analytical envelopes (Figures 13-15).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from services.cli.command_options import check_png_target
from shared.option_types import float_in

if TYPE_CHECKING:
    from shared.model import EventMetrics, JointConstants, Share

NAME = "model"
HELP = "the analytical stick-slip model of a joint (report, plot, rig validation)"

DEFAULT_JOINT = Path("config/joints/paper-section-5-2.toml")
DEFAULT_SPEED_RAD_S = 0.5
DEFAULT_TARGET_FORCE_N = 56_000.0
DEFAULT_TARGET_TORQUE_NM = 200.0

#: what a tightening tool can be asked for: motor speed (1 mrad/s to ~9500 rpm), preload up
#: to 10 MN (beyond an M100 bolt), torque up to 100 kNm (a large hydraulic wrench)
SPEED_RAD_S = float_in(0.001, 1000.0, "rad/s")
TARGET_FORCE_N = float_in(0.0, 1e7, "N", low_allowed=False)
TARGET_TORQUE_NM = float_in(0.0, 1e5, "Nm", low_allowed=False)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--joint",
        type=Path,
        default=DEFAULT_JOINT,
        help=f"joint file (default: {DEFAULT_JOINT})",
    )
    parser.add_argument(
        "--speed",
        type=SPEED_RAD_S,
        default=DEFAULT_SPEED_RAD_S,
        metavar="RAD_S",
        help=f"constant motor speed φ̇_m in rad/s (default: {DEFAULT_SPEED_RAD_S})",
    )
    parser.add_argument(
        "--target-force",
        type=TARGET_FORCE_N,
        default=None,
        metavar="N",
        help="target preload in N (default: 56000 when no target is given)",
    )
    parser.add_argument(
        "--target-torque",
        type=TARGET_TORQUE_NM,
        default=None,
        metavar="NM",
        help="target torque in Nm (default: 200 when no target is given)",
    )
    parser.add_argument("--json", action="store_true", help="print JSON instead of text")
    parser.add_argument(
        "--plot", type=Path, default=None, metavar="OUT.png", help="draw the bounds to a PNG"
    )
    parser.add_argument(
        "--validate",
        action="store_true",
        help="simulate a grid of joints on the rig and check them against the envelopes",
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=None,
        metavar="report.png",
        help="with --validate: draw measured events over the envelopes to a PNG",
    )


def run(args: argparse.Namespace) -> int:
    from shared.config import load_joint
    from shared.errors import InputError

    if args.validate:
        return _validate(args)
    if args.out is not None:
        raise InputError("--out goes with --validate; for the report use --plot OUT.png")
    target_force_n, target_torque_nm = args.target_force, args.target_torque
    if target_force_n is None and target_torque_nm is None:
        target_force_n, target_torque_nm = DEFAULT_TARGET_FORCE_N, DEFAULT_TARGET_TORQUE_NM
    joint = load_joint(args.joint)

    from shared.model import format_report, joint_report

    report = joint_report(joint, args.speed, target_force_n, target_torque_nm)
    if args.plot is not None:
        check_png_target(args.plot, "the plot")
        from shared.model import draw_joint_figure

        draw_joint_figure(joint, args.speed, report["time"]["model_time_at_target_s"], args.plot)
        report["plot"] = str(args.plot)
    if args.json:
        json.dump(report, sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        print(format_report(report))
        if args.plot is not None:
            print(f"\nplot written to {args.plot}")
    return 0


def _validate(args: argparse.Namespace) -> int:
    """Tighten the validation grid on the rig; report the shares inside the envelopes."""
    from shared.config import load_joint
    from shared.model import JointConstants, JointModel, envelope_shares

    if args.out is not None:
        check_png_target(args.out, "the figure")
    rows = []
    reference = None
    for joint_file, length_mm, speed in VALIDATION_GRID:
        joint = load_joint(joint_file)
        joint = joint.model_copy(
            update={"extension": joint.extension.model_copy(update={"length_mm": length_mm})}
        )
        model = JointModel(JointConstants.of(joint), speed)
        metrics = _simulate(JointConstants.of(joint), speed)
        shares = envelope_shares(metrics, model)
        rows.append((joint.name, length_mm, speed, len(metrics.k1), shares))
        if reference is None:
            reference = (joint.name, model, metrics)
    if args.json:
        out = [
            {
                "joint": name,
                "extension_length_mm": length_mm,
                "motor_speed_rad_s": speed,
                "events": count,
                "shares": {key: vars_of(value) for key, value in shares.items()},
            }
            for name, length_mm, speed, count, shares in rows
        ]
        json.dump(out, sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        print(_format_validation(rows))
    if args.out is not None and reference is not None:
        from shared.model import draw_validation_figure

        draw_validation_figure(*reference, args.out)
        if not args.json:
            print(f"\nfigure written to {args.out}")
    return 0


#: (joint file, extension length in mm, motor speed in rad/s) of ``--validate``
VALIDATION_GRID = (
    (Path("config/joints/paper-section-5-2.toml"), 110.0, 0.5),
    (Path("config/joints/paper-section-5-2.toml"), 110.0, 2.0),
    (Path("config/joints/paper-section-5-2.toml"), 350.0, 0.5),
    (Path("config/joints/paper-section-3-4.toml"), 200.0, 0.5),
    (Path("config/joints/paper-section-3-4.toml"), 200.0, 2.0),
    (Path("config/joints/paper-section-3-4.toml"), 500.0, 1.0),
)
VALIDATION_START_FORCE_N = 10_000.0
VALIDATION_TARGET_FORCE_N = 56_000.0
VALIDATION_SEED = 2018

EXPLANATIONS = {
    "frequency": (
        "f_ss above the max: μ_stick scatters per event (rig.mu_stick_scatter), so a slip"
        " can start before the mean stick limit; Δt is also quantized to the 1 ms sample."
        " Below the min: never expected (a slip cannot exceed φ_0,stick)."
    ),
    "force_step": (
        "ΔF below the min: a slip stopped early (re-stuck on a lower μ_stick draw) or the"
        " previous one overshot; ΔF is the true preload, so noise plays no part."
    ),
    "torque_drop": (
        "ΔT below the min: peak and trough are the 1 kHz samples nearest them, with"
        " rig.torque_noise_nm of noise; the peak is read up to 1 ms before the slip"
        " (k_e φ̇_m · 1 ms low, more at high speed) and a slip lasts about π/ω_d ≈ 1-2 ms,"
        " so the trough can fall between samples. Inertia overshoot makes a slip run past"
        " φ_b,max (up to 2 Δφ_b undamped), which stays inside the max."
    ),
    "k1": "as f_ss",
    "k2": "as ΔF and f_ss",
    "k3": "as ΔT",
}


def vars_of(share: Share) -> dict[str, int]:
    return {key: getattr(share, key) for key in ("below", "inside", "above")}


def _simulate(constants: JointConstants, speed: float) -> EventMetrics:
    """One rig run from 10 kN to 56 kN; the metrics of its slip events."""
    import numpy as np

    from services.rig.physics import TighteningPhysics
    from shared.config import Program, RigSection
    from shared.model import event_metrics

    program = Program(
        id=1,
        name="validate",
        target_force_n=VALIDATION_TARGET_FORCE_N,
        motor_speed_rad_s=speed,
        start_force_n=VALIDATION_START_FORCE_N,
        max_torque_nm=5000.0,
        max_angle_deg=1e6,
        max_time_s=60.0,
    )
    physics = TighteningPhysics(constants, program, RigSection(), seed=VALIDATION_SEED)
    times, torques, slips, model_times = [], [], [], []
    while physics.true_force_n < VALIDATION_TARGET_FORCE_N and physics.time_s < 60.0:
        sample = physics.advance()
        times.append(sample.time_s)
        torques.append(sample.torque_nm)
        slips.append(physics.slip_count)
        model_times.append(physics.motor_angle_rad / speed)
    slip = np.asarray(slips)
    torque = np.asarray(torques)
    onsets = np.flatnonzero(np.diff(slip) > 0) + 1  # first sample after a slip began
    peaks = torque[onsets - 1]
    ends = np.append(onsets[1:], len(torque))
    troughs = np.array([torque[a:b].min() for a, b in zip(onsets, ends, strict=True)])
    plateaus = np.asarray(physics.plateau_forces_n)
    return event_metrics(
        np.asarray(times)[onsets] - 1e-3 / 2,
        np.asarray(model_times)[onsets],
        peaks,
        troughs,
        plateaus,
        speed,
    )


def _format_validation(rows: list[tuple[str, float, float, int, dict[str, Share]]]) -> str:
    keys = ("frequency", "force_step", "torque_drop", "k1", "k2", "k3")
    lines = [
        "rig runs 10 kN -> 56 kN against the full-relief envelopes (eqs. 21-26, 34-39)",
        "share inside per metric (below / above the envelope in brackets)",
        "",
        f"{'joint':<34} {'l_e':>5} {'φ̇_m':>5} {'events':>6}  "
        + "  ".join(f"{key:>15}" for key in keys),
    ]
    outside: set[str] = set()
    for name, length_mm, speed, count, shares in rows:
        cells = []
        for key in keys:
            share = shares[key]
            below, inside, above = share.below, share.inside, share.above
            if below or above:
                outside.add(key)
            cells.append(f"{inside / max(count, 1):5.0%} ({below}/{above})".rjust(15))
        lines.append(
            f"{name[:34]:<34} {length_mm:5.0f} {speed:5.2g} {count:6d}  " + "  ".join(cells)
        )
    if outside:
        lines += ["", "outside the envelope, why:"]
        lines += [f"  {key}: {EXPLANATIONS[key]}" for key in keys if key in outside]
    return "\n".join(lines)
