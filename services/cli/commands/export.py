"""``boltwatch export RUN.mcap [--out TRACE.csv] [--run ID]``: a recording's samples as CSV."""

from __future__ import annotations

import argparse
from pathlib import Path

from services.cli.command_options import (
    add_recording_argument,
    add_run_option,
    warn_damaged_recording,
)

NAME = "export"
HELP = "write the samples of a recorded run as a trace CSV (what 'boltwatch predict' reads)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Write the samples of one run of an MCAP recording as the trace CSV "
        "time_s,torque_nm,angle_deg,force_n (time_s from the run's first sample). "
        "A damaged recording (recorder killed) exports what is readable, with a warning."
    )
    add_recording_argument(parser)
    parser.add_argument(
        "--out",
        type=Path,
        default=None,
        metavar="TRACE.csv",
        help="where to write the trace (default: RUN.csv beside the recording)",
    )
    add_run_option(parser, "run id to export (default: the run with the most samples in the file)")


def run(args: argparse.Namespace) -> int:
    from shared.recordings.mcap import export_trace

    report = export_trace(args.recording, args.out, args.run)
    if not report.complete:
        warn_damaged_recording(NAME, report.state, "exported what is readable")
    print(f"wrote {report.rows} samples of run {report.run_id} to {report.target}")
    return 0
