"""``boltwatch predict TRACE.csv --target-force N``: the predictor over a recorded trace.

Runs the same predictor core as the live service, sample by sample, and
prints JSON Lines on stdout (contract in docs/design.md): one
``{"type": "event", "time_s": ...}`` per stick-slip event with its figures
and predictions, one ``{"type": "stop", "time_s": ..., "reason": ...}`` per
stop decision (``time_s`` is the sample at which it was decided).
``--target-torque`` alone means torque-only mode. A summary of the input
guard and the prediction scores goes to stderr with ``--summary``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

NAME = "predict"
HELP = "run the real-time predictor over a trace CSV and print events and stops as JSON Lines"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "trace", type=Path, help="CSV with header time_s,torque_nm,angle_deg,force_n"
    )
    parser.add_argument(
        "--target-force", type=float, default=None, metavar="N", help="target preload, N"
    )
    parser.add_argument(
        "--target-torque",
        type=float,
        default=None,
        metavar="NM",
        help="target torque, Nm (alone: torque-only mode)",
    )
    parser.add_argument(
        "--joint",
        type=Path,
        default=None,
        metavar="FILE",
        help="joint file (TOML) of the expected joint, for the K1-K3 band",
    )
    parser.add_argument(
        "--window",
        type=int,
        default=None,
        metavar="N",
        help="samples in the peak-detection window (default 5, see the predictor docs)",
    )
    parser.add_argument(
        "--config",
        type=Path,
        default=None,
        metavar="STATION.toml",
        help="decide as this station decides --program: its targets, limits, motor speed, the "
        "program's joint, its DBC's sensor range and [predictor] section (options given here "
        "replace the file's)",
    )
    parser.add_argument(
        "--program", type=int, default=None, metavar="ID", help="the program of --config"
    )
    parser.add_argument(
        "--dbc",
        type=Path,
        default=None,
        metavar="FILE",
        help="the station's CAN database: values outside what its Torque, Angle and Force "
        "signals can carry are bad input, counted and never used (default: the range of the "
        "contract DBC, config/can/station.dbc)",
    )
    parser.add_argument(
        "--summary",
        action="store_true",
        help="print input counts (bad, implausible, held values) and prediction errors to "
        "stderr, as one JSON object",
    )


def run(args: argparse.Namespace) -> int:
    import json
    import sys

    from services.cli.predict_settings import predict_settings
    from shared.contract import read_trace
    from shared.stickslip import PredictorCore, json_safe, output_record, replay

    trace = read_trace(args.trace)
    settings, note = predict_settings(args, trace.has_force)
    if note is not None:
        print(f"boltwatch predict: {note}", file=sys.stderr)
    core = PredictorCore(settings)
    out = sys.stdout
    for output in replay(core, trace):
        out.write(json.dumps(output_record(output), allow_nan=False) + "\n")
    out.flush()
    if args.summary:
        summary = {
            "samples": len(trace),
            "events": core.events,
            "process_intensity": core.process_intensity,
            "input": core.input_report.as_dict(),
            "prediction_errors": core.scores.summary(),
        }
        print(json.dumps(json_safe(summary), allow_nan=False), file=sys.stderr)
    return 0
