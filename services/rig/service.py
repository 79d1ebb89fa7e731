"""``boltwatch serve rig``: the simulated tool controller and sensors on the station's CAN bus.

Loads the station file once, opens the configured bus (closed on exit) and
runs :class:`~services.rig.realtime.RealtimeRig` in the work thread of its
:class:`~shared.runtime.service_skeleton.ServiceSkeleton`: ``--runs N`` exits 0
after N runs, otherwise it runs until SIGINT/SIGTERM (the loop looks at the
stop flag every sample period, so no wake is needed).

Like every service, the rig holds the liveliness token
``boltwatch/<station>/health/rig`` on a zenoh session opened from the station
file, so ``boltwatch up`` and ``status`` see it. A rig on a ``virtual`` bus is
the exception: that bus lives inside one process, no station service can
reach the rig, so it announces nothing (and needs no zenoh: unit tests).

A station of several spindles (``[station] spindles``) is a multi-spindle
system (:mod:`services.rig.multi_spindle`): ``--runs N`` is N synchronised
cycles, each a run of every spindle.

On zenoh it also stands in for the line's PLC: the id of each part
(``[rig] bolts_per_part`` runs each) goes on ``boltwatch/<station>/part``
before the part's first run (:mod:`services.rig.part_scanner`), so the
station's results name their parts. ``bolts_per_part = 0``: no parts.
"""

from __future__ import annotations

import argparse
import logging
import threading
import time

from services.rig.frames import RigFrames
from services.rig.multi_spindle import MultiSpindleRig
from services.rig.part_scanner import PartScanner
from services.rig.realtime import RealtimeRig, ToolIdentity
from services.rig.selection import choose_program, choose_seed
from shared.config import load_station
from shared.contract import StationDatabase
from shared.errors import ConfigError
from shared.model import JointConstants
from shared.runtime import RIG_PRIORITY, ServiceSkeleton, open_bus, use_realtime_priority

LOG = logging.getLogger(__name__)

RUN_ID_MAX = 0xFFFF_FFFF  # RunId is 32 bits on CAN


def main(args: argparse.Namespace) -> int:
    if getattr(args, "controller", "can") == "openprotocol":
        from services.rig.openprotocol.controller_service import main as openprotocol_main

        return openprotocol_main(args)
    station = load_station(args.config)
    config = station.config
    program = choose_program(station, args.program)
    if args.runs is not None and args.runs < 1:
        raise ConfigError(f"--runs must be at least 1 (got {args.runs})")
    seed = choose_seed(args.seed, config.rig.seed)
    first_run_id = args.first_run_id if args.first_run_id is not None else int(time.time())
    spindles = config.station.spindles
    last_run_id = first_run_id + (args.runs or 1) * spindles - 1
    if first_run_id < 0 or last_run_id > RUN_ID_MAX:
        raise ConfigError(f"--first-run-id must keep run ids within 0..{RUN_ID_MAX}")
    frames = RigFrames(StationDatabase(station.dbc_path))
    constants = JointConstants.of(station.joint_of(program.id))
    announces_parts = config.can.interface != "virtual" and config.rig.bolts_per_part > 0
    LOG.info(
        "rig: station %s, %s, program %d (%s), first run %d, seed %d, runs %s, %s",
        config.station.id,
        f"{spindles} spindles (runs are cycles)" if spindles > 1 else "one spindle",
        program.id,
        program.name,
        first_run_id,
        seed,
        args.runs if args.runs is not None else "until stopped",
        f"{config.rig.bolts_per_part} bolts per part" if announces_parts else "no part ids",
    )
    with ServiceSkeleton("rig") as skeleton:
        bus = skeleton.device(open_bus(config.can))
        parts = None
        if config.can.interface != "virtual":
            skeleton.open_session(config.zenoh)
            if announces_parts:
                parts = PartScanner(skeleton, config.station.id, config.rig, per_cycle_of=spindles)
            skeleton.health_token(config.station.id, "rig")
        identity = ToolIdentity(config.station.tool_id, config.station.has_force_sensor)
        rig: RealtimeRig
        if spindles > 1:
            rig = MultiSpindleRig(
                bus,
                frames,
                constants,
                config.rig,
                identity,
                tool_ids=[config.station.tool_of(k) for k in range(1, spindles + 1)],
                id_stride=config.can.spindle_id_stride,
            )
        else:
            rig = RealtimeRig(bus, frames, constants, config.rig, identity)

        def work(stop: threading.Event) -> None:
            # the tool is the reference a stop is measured against: it keeps its own pace
            use_realtime_priority(RIG_PRIORITY, "rig")
            rig.run_many(program, first_run_id, seed, stop, runs=args.runs, parts=parts)

        return skeleton.run(work)
