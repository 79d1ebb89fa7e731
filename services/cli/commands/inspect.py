"""``boltwatch inspect RUN.mcap [--out RUN.png]``: a picture of a recorded run."""

from __future__ import annotations

import argparse
from pathlib import Path

NAME = "inspect"
HELP = "plot a recorded run (torque, force, detected peaks and plateaus) as a PNG"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Draw torque and preload force over time of one run of an MCAP recording, with each "
        "detected stick-slip peak and plateau and the stop decision, into a PNG. For "
        "interactive viewing open the .mcap in Foxglove (it needs no plug-in)."
    )
    parser.add_argument("recording", type=Path, metavar="RUN.mcap", help="the recording")
    parser.add_argument(
        "--out", type=Path, default=None, metavar="RUN.png", help="default: beside the recording"
    )
    parser.add_argument("--run", type=int, default=None, metavar="ID", help="run id to draw")


def run(args: argparse.Namespace) -> int:
    from services.recorder.run_plot import plot_run

    target = args.out or args.recording.with_suffix(".png")
    samples, events = plot_run(args.recording, target, args.run)
    print(f"wrote {target}: {samples} samples, {events} stick-slip events")
    return 0
