"""``boltwatch inspect RUN.mcap [--out RUN.png]``: a picture of a recorded run."""

from __future__ import annotations

import argparse
from pathlib import Path

from services.cli.command_options import (
    add_recording_argument,
    add_run_option,
    check_png_target,
    warn_damaged_recording,
)

NAME = "inspect"
HELP = "draw a recorded run as a post-mortem PNG of the paper's figures (10, 13-15, 22, 23)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Draw one run of an MCAP recording into a one-page PNG report after the paper's "
        "figures: torque and preload with detected peaks, plateaus and the stop decision "
        "(Fig. 10); f_ss, force step, torque drop and K1-K3 per event (Figs. 13-15); the "
        "errors of the 1st-3rd predictions (Figs. 22, 23, eqs. 61-63). With the joint and "
        "program metadata in the file, the analytical bounds are drawn too. For interactive "
        "viewing open the .mcap in Foxglove (it needs no plug-in)."
    )
    add_recording_argument(parser)
    parser.add_argument(
        "--out", type=Path, default=None, metavar="RUN.png", help="default: beside the recording"
    )
    add_run_option(
        parser,
        "run id to draw (default: the run with the most samples; the output names the others)",
    )


def run(args: argparse.Namespace) -> int:
    from services.recorder.post_mortem.run_plot import draw_run

    target = args.out or args.recording.with_suffix(".png")
    check_png_target(target, "the report")
    run = draw_run(args.recording, target, args.run)
    if not run.complete:
        warn_damaged_recording(NAME, run.state, "drew what is readable")
    others = [other for other in run.runs_in_file if other != run.run_id]
    also = f" (other runs in the file: {', '.join(map(str, others))})" if others else ""
    print(
        f"wrote {target}: run {run.run_id}, {len(run.samples)} samples, "
        f"{len(run.events)} stick-slip events{also}"
    )
    return 0
