"""``boltwatch simulate``: one simulated tightening, as fast as it computes, to a CSV trace.

The rig's physics and tool controller without clock or CAN: the controller
stops the motor the conventional way (force target, else torque target) or,
with ``--no-shutoff``, only at the program's hard limits, so that offline
prediction (``boltwatch predict``) can be seen past the target. The trace is
the offline contract ``time_s,torque_nm,angle_deg,force_n`` (force empty on a
station without a force sensor).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from services.cli.command_options import add_station_file_option

NAME = "simulate"
HELP = "simulate one tightening offline and write its trace (CSV) for 'boltwatch predict'"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_station_file_option(parser)
    parser.add_argument(
        "--program", type=int, default=None, help="program id (default: the first program)"
    )
    parser.add_argument(
        "--seed", type=int, default=None, help="default: [rig] seed, else a fresh one"
    )
    parser.add_argument(
        "--no-shutoff",
        action="store_true",
        help="do not stop at the target: run until a hard limit (max torque/force/angle/time)",
    )
    parser.add_argument("--out", type=Path, required=True, help="trace file to write (CSV)")


def run(args: argparse.Namespace) -> int:
    from services.rig.controller import RunController
    from services.rig.physics import TighteningPhysics
    from services.rig.selection import choose_program, choose_seed
    from shared.config import load_station
    from shared.contract import write_trace
    from shared.model import JointConstants

    station = load_station(args.config)
    config = station.config
    program = choose_program(station, args.program)
    seed = choose_seed(args.seed, config.rig.seed)
    has_force = config.station.has_force_sensor
    physics = TighteningPhysics(
        JointConstants.of(station.joint_of(program.id)), program, config.rig, seed
    )
    controller = RunController(
        physics,
        program,
        run_id=0,
        settle_time_s=config.rig.settle_time_s,
        has_force_sensor=has_force,
        shutoff=not args.no_shutoff,
    )
    controller.start()
    rows: list[tuple[float, float, float, float | None]] = []
    while not controller.finished:
        m = controller.tick()
        rows.append((m.time_s, m.torque_nm, m.angle_deg, m.force_n if has_force else None))
    count = write_trace(args.out, rows)  # an OSError names the file (boltwatch main)
    print(
        f"{count} samples written to {args.out}: {physics.time_s:.3f} s, "
        f"{physics.slip_count} slips, final force {physics.true_force_n:.0f} N "
        f"(program {program.id}, seed {seed}, stopped by {controller.stop_source})"
    )
    return 0
