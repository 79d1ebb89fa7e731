"""``boltwatch serve SERVICE --config FILE``: run one long-running service.

Each service package ``services/<name>/`` provides ``arguments.py`` with
``add_arguments(parser)`` (light: no heavy imports, so ``--help`` is fast) and
``service.py`` with ``main(args) -> int``, which loads the station file named
by ``args.config`` once and passes it down. The predictor and the recorder
take several station files (``args.config`` is then a list): one process
serves every station named.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from types import ModuleType

from services.acquisition import arguments as acquisition_arguments
from services.cli.command_options import add_station_file_option
from services.dashboard import arguments as dashboard_arguments
from services.opcua import arguments as opcua_arguments
from services.openprotocol import arguments as openprotocol_arguments
from services.predictor import arguments as predictor_arguments
from services.recorder import arguments as recorder_arguments
from services.rig import arguments as rig_arguments
from services.router import arguments as router_arguments

NAME = "serve"
HELP = (
    "run one long-running service (rig, acquisition, predictor, recorder, router, openprotocol, "
    "dashboard, opcua)"
)

#: service name -> its arguments module (light: no heavy imports, so ``--help`` is fast)
SERVICES: dict[str, ModuleType] = {
    "rig": rig_arguments,
    "acquisition": acquisition_arguments,
    "predictor": predictor_arguments,
    "recorder": recorder_arguments,
    "router": router_arguments,
    "openprotocol": openprotocol_arguments,
    "dashboard": dashboard_arguments,
    "opcua": opcua_arguments,
}

LOG_LEVELS = ("DEBUG", "INFO", "WARNING", "ERROR")

#: services of the line that one process runs for several stations (``--config A B ...``)
MULTI_STATION = ("predictor", "recorder", "dashboard", "opcua")

SERVICE_HELP = {
    "rig": "the simulated tool controller and sensors on the CAN bus",
    "acquisition": "CAN frames in, samples out on zenoh, stop decisions back to CAN",
    "predictor": "the real-time stick-slip predictor: events, intensity, stop decisions",
    "recorder": "MCAP files per run",
    "router": "the line's zenoh router that stations connect to",
    "openprotocol": "a tightening controller's results and curves over Open Protocol (TCP), "
    "published as the station's runs",
    "dashboard": "the line's web page: services, results, stop reasons, tool wear, alerts, live",
    "opcua": "the line's results over OPC UA for industrial joining (IJT): one joining system "
    "per station, results and result-ready events, results by id with their traces, tools with "
    "their counters",
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    services = parser.add_subparsers(dest="service", metavar="SERVICE", required=True)
    for name, arguments in SERVICES.items():
        sub = services.add_parser(name, help=SERVICE_HELP[name], description=SERVICE_HELP[name])
        if name in MULTI_STATION:
            add_station_file_option(
                sub, "station file(s): one process serves every station named", several=True
            )
        elif name != "router":
            add_station_file_option(sub)
        sub.add_argument(
            "--log-level",
            type=str.upper,
            choices=LOG_LEVELS,
            default=None,
            help="DEBUG, INFO (default), WARNING, ERROR",
        )
        sub.set_defaults(command_label=f"{NAME} {name}")
        arguments.add_arguments(sub)


def run(args: argparse.Namespace) -> int:
    from shared.runtime import follow_supervisor, setup_logging

    setup_logging(args.service, args.log_level)
    follow_supervisor()  # started by boltwatch up: stop when it dies
    return _service_main(args.service)(args)


def _service_main(service: str) -> Callable[[argparse.Namespace], int]:
    """The ``main`` of a service, imported only when that service runs (each is heavy)."""
    if service == "rig":
        from services.rig.service import main as rig_main

        return rig_main
    if service == "acquisition":  # the station's predictor may decide in it (edge)
        from services.acquisition.service import main as acquisition_main
        from services.predictor.edge_predictor import EdgePredictor

        return lambda args: acquisition_main(args, decider_factory=EdgePredictor)
    if service == "predictor":
        from services.predictor.service import main as predictor_main

        return predictor_main
    if service == "openprotocol":
        from services.openprotocol.service import main as openprotocol_main

        return openprotocol_main
    if service == "recorder":
        from services.recorder.service import main as recorder_main

        return recorder_main
    if service == "dashboard":
        from services.dashboard.service import main as dashboard_main

        return dashboard_main
    if service == "opcua":
        from services.opcua.service import main as opcua_main

        return opcua_main
    from services.router.service import main as router_main

    return router_main
