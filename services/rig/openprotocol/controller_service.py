"""``boltwatch serve rig --controller openprotocol``: the simulated rig as an Open Protocol
controller, a TCP server on the station's ``[openprotocol]`` host:port.

Loads the station file once, listens (a port that cannot be listened on is
a ``TransportError``: one line, no traceback), holds the rig's liveliness token
``boltwatch/<station>/health/rig`` on a zenoh session from the station file
as the CAN rig does, and runs :class:`~.simulated_controller.SimulatedController`
in the work thread of its :class:`~shared.runtime.service_skeleton.ServiceSkeleton`:
``--runs N`` ends (status 0) once an integrator has had all N tightenings
(pushed and acknowledged, or fetched by id after it was away), otherwise it
runs until SIGINT/SIGTERM.
"""

from __future__ import annotations

import argparse
import logging

from services.rig.openprotocol.simulated_controller import SimulatedController
from services.rig.openprotocol.tightening_counter import TighteningCounter
from services.rig.selection import choose_program, choose_seed
from shared.config import load_station
from shared.errors import ConfigError
from shared.runtime import ServiceSkeleton, Stop

LOG = logging.getLogger(__name__)


def main(args: argparse.Namespace) -> int:
    station = load_station(args.config)
    config = station.config
    program = choose_program(station, args.program)
    if args.runs is not None and args.runs < 1:
        raise ConfigError(f"--runs must be at least 1 (got {args.runs})")
    seed = choose_seed(args.seed, config.rig.seed)
    counter = TighteningCounter.of_station(station.recordings_folder, config.station.id)
    first_id = args.first_run_id if args.first_run_id is not None else counter.last() + 1
    controller = SimulatedController(
        station,
        program,
        first_tightening_id=first_id,
        seed=seed,
        runs=args.runs,
        wait_for_integrator=args.wait_for_integrator,
        counter=counter,
    )
    section = config.openprotocol
    assert section is not None  # SimulatedController refused a station without it
    LOG.info(
        "rig as an Open Protocol controller on %s:%d: station %s, program %d (%s), "
        "first tightening %d, seed %d, runs %s",
        section.host,
        controller.server.port,
        config.station.id,
        program.id,
        program.name,
        first_id,
        seed,
        args.runs if args.runs is not None else "until stopped",
    )
    with ServiceSkeleton("rig") as skeleton:
        skeleton.on_stop(Stop.DEVICE, controller.close)
        skeleton.open_session(config.zenoh)
        skeleton.health_token(config.station.id, "rig")
        return skeleton.run(controller.run)
