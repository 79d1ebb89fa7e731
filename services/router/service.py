"""``boltwatch serve router``: a zenoh session in router mode.

Stations connect to it as clients (``[zenoh] mode = "client"``). In a plant
the official ``eclipse/zenoh`` router image does the same job (see
docker-compose.yml); this one needs nothing but the Python wheel.
"""

from __future__ import annotations

import argparse
import logging
import threading

from shared.service_runtime import ServiceRunner
from shared.zenoh_session import open_from, zenoh_config

LOG = logging.getLogger(__name__)

DEFAULT_LISTEN = "tcp/127.0.0.1:7447"


def main(args: argparse.Namespace) -> int:
    endpoints = args.listen or [DEFAULT_LISTEN]
    with open_from(zenoh_config("router", listen=endpoints)):
        LOG.info("zenoh router listening on %s", ", ".join(endpoints))

        def work(stop: threading.Event) -> None:
            stop.wait()

        return ServiceRunner("router", work).run()
