"""``boltwatch predict TRACE.csv --target-force N``: the predictor over a recorded trace.

Runs the same predictor core as the live service, sample by sample, and
prints JSON Lines on stdout (contract in DESIGN.md): one
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
    import math
    import sys

    from services.predictor.core import DEFAULT_WINDOW_SAMPLES, PredictorCore, PredictorSettings
    from services.predictor.trace_replay import json_safe, output_record, replay
    from shared.errors import InputError
    from shared.sensor_range import CONTRACT_RANGE, SensorRange
    from shared.trace import read_trace

    if args.target_force is None and args.target_torque is None:
        raise InputError("give --target-force N, --target-torque NM, or both")
    for name in ("target_force", "target_torque"):
        value = getattr(args, name)
        if value is not None and not (math.isfinite(value) and value > 0):
            raise InputError(
                f"--{name.replace('_', '-')} must be a finite number > 0 (got {value})"
            )
    window = args.window if args.window is not None else DEFAULT_WINDOW_SAMPLES
    if not 3 <= window <= 200:
        raise InputError(f"--window must be between 3 and 200 samples (got {window})")
    constants = None
    if args.joint is not None:
        from shared.config import load_joint
        from shared.errors import ConfigError
        from shared.model import JointConstants

        try:
            constants = JointConstants.of(load_joint(args.joint))
        except ConfigError as err:
            raise InputError(str(err)) from err
    sensor_range = CONTRACT_RANGE
    if args.dbc is not None:
        from shared.can_database import StationDatabase
        from shared.errors import CanDatabaseError

        try:
            sensor_range = SensorRange.of_database(StationDatabase(args.dbc))
        except CanDatabaseError as err:
            raise InputError(str(err)) from err
    trace = read_trace(args.trace)
    has_force = args.target_force is not None and trace.has_force
    settings = PredictorSettings(
        target_force_n=args.target_force if has_force else None,
        target_torque_nm=args.target_torque,
        has_force=has_force,
        window_samples=window,
        constants=constants,
        sensor_range=sensor_range,
    )
    if args.target_force is not None and not trace.has_force:
        if args.target_torque is None:
            raise InputError(
                f"{args.trace}: no force values in the trace; give --target-torque for "
                "torque-only mode"
            )
        print(
            f"boltwatch predict: {args.trace}: no force values, torque-only mode",
            file=sys.stderr,
        )
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
