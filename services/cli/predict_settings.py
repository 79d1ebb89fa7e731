"""What ``boltwatch predict`` decides with: its options, or a station's program.

``--config STATION.toml --program ID`` gives the core exactly the settings
the live station decides that program with (targets, hard limits, motor
speed, the program's joint for the eq. 71 band, the DBC's sensor range, the
``[predictor]`` section), so the prediction over a recorded run is the live
decision (live = offline: ``docs/explanation/algorithm.md``). Explicit ``--target-force``,
``--target-torque``, ``--joint``, ``--window`` and ``--dbc`` replace what the
station file says. Without ``--config``, a target is required.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
from pathlib import Path

from shared.contract import SensorRange
from shared.errors import BoltwatchError, InputError
from shared.model import JointConstants
from shared.stickslip import DEFAULT_WINDOW_SAMPLES, PredictorSettings


def predict_settings(
    args: argparse.Namespace, trace_has_force: bool
) -> tuple[PredictorSettings, str | None]:
    """(the core's settings for this ``predict``, a note for the user or None); InputError
    naming the option when an option is bad."""
    for name in ("target_force", "target_torque"):
        value = getattr(args, name)
        if value is not None and not (math.isfinite(value) and value > 0):
            raise InputError(
                f"--{name.replace('_', '-')} must be a finite number > 0 (got {value})"
            )
    if args.window is not None and not 3 <= args.window <= 200:
        raise InputError(f"--window must be between 3 and 200 samples (got {args.window})")
    if args.config is not None:
        base = _station_settings(args)
    elif args.target_force is None and args.target_torque is None:
        raise InputError("give --target-force N, --target-torque NM, or both (or --config)")
    else:
        base = PredictorSettings(target_force_n=None, target_torque_nm=None, has_force=True)
    changes: dict[str, float | int | JointConstants | SensorRange | None] = {}
    if args.target_force is not None:
        changes["target_force_n"] = args.target_force
    if args.target_torque is not None:
        changes["target_torque_nm"] = args.target_torque
    if args.window is not None or args.config is None:
        changes["window_samples"] = args.window or DEFAULT_WINDOW_SAMPLES
    if args.joint is not None:
        changes["constants"] = _joint_constants(args.joint)
    if args.dbc is not None:
        changes["sensor_range"] = _dbc_range(args.dbc)
    settings = dataclasses.replace(base, **changes)  # type: ignore[arg-type]  # mixed field types
    wants_force = settings.has_force and settings.target_force_n is not None
    has_force = wants_force and trace_has_force
    if not has_force and settings.target_torque_nm is None:
        raise InputError(
            f"{args.trace}: no force values in the trace (or none measured at the station); "
            "give --target-torque for torque-only mode"
        )
    note = (
        f"{args.trace}: no force values, torque-only mode"
        if wants_force and not has_force
        else None
    )
    settings = dataclasses.replace(
        settings,
        has_force=has_force,
        target_force_n=settings.target_force_n if has_force else None,
        max_force_n=settings.max_force_n if has_force else None,
    )
    return settings, note


def _station_settings(args: argparse.Namespace) -> PredictorSettings:
    from shared.config import load_station

    if args.program is None:
        raise InputError("--config needs --program ID: the program whose settings to use")
    station = load_station(args.config)
    try:
        program = station.config.program(args.program)
    except KeyError as err:
        raise InputError(f"{args.config}: {err.args[0]} (--program)") from err
    return PredictorSettings.of(
        program,
        station.config.predictor,
        station.config.station.has_force_sensor,
        JointConstants.of(station.joint_of(program.id)),
        station.sensor_range,
    )


def _joint_constants(path: Path) -> JointConstants:
    from shared.config import load_joint

    try:
        return JointConstants.of(load_joint(path))
    except BoltwatchError as err:
        raise InputError(str(err)) from err


def _dbc_range(path: Path) -> SensorRange:
    from shared.contract import StationDatabase

    try:
        return SensorRange.of_database(StationDatabase(path))
    except BoltwatchError as err:
        raise InputError(str(err)) from err
