"""``boltwatch status [--config FILE | --connect ENDPOINT] [--listen-s S] [--json]``.

Joins the line's zenoh router as a client, listens to every station's topics
(``boltwatch/*/**``: ``quality/alert`` has two chunks) for ``--listen-s`` seconds,
then asks which liveliness tokens ``boltwatch/*/health/*`` exist, and prints every station seen (see
:mod:`shared.line_status.station_status` for what each figure means). Exit 0 when
the router answered (even if no station is alive), 2 when it is unreachable.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TYPE_CHECKING

from services.cli.command_options import DEFAULT_STATION_FILE
from shared.option_types import seconds

if TYPE_CHECKING:
    import zenoh

    from shared.line_status import StatusReport

NAME = "status"
HELP = (
    "which stations and services are alive, sample rate, bus faults, last run and "
    "decision, recorder lag and health"
)

LIVELINESS_TIMEOUT_S = 2.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Connect to the zenoh router (the endpoint of the station file's [zenoh] connect, "
        "or --connect), listen to every station for a moment and print, per station: "
        "services alive, samples per second, bus gaps and bad frames, the last run, the "
        "last stop decision, the last run summary, and the recorder's lag and write "
        "health (its RecorderStats, once a second). Runs, decisions and summaries are "
        "shown only if they happened while listening; lengthen --listen-s to catch one."
    )
    where = parser.add_mutually_exclusive_group()
    where.add_argument(
        "--config",
        type=Path,
        default=None,
        metavar="FILE",
        help=(
            f"station file whose [zenoh] connect names the router, with its tls_* files for "
            f"a router with mutual TLS (default: {DEFAULT_STATION_FILE})"
        ),
    )
    where.add_argument(
        "--connect",
        default=None,
        metavar="ENDPOINT",
        help="router endpoint, e.g. tcp/127.0.0.1:7447 (instead of a station file; no TLS)",
    )
    parser.add_argument(
        "--listen-s",
        type=seconds,
        default=2.0,
        metavar="S",
        help="seconds to listen for messages (default: 2.0; BusStats come once a second)",
    )
    parser.add_argument("--json", action="store_true", help="print one JSON object instead")


def run(args: argparse.Namespace) -> int:
    from services.cli.router_client import router_client
    from services.cli.station_status_text import format_report
    from shared.line_status import to_json

    endpoint, config = router_client(args.config or DEFAULT_STATION_FILE, args.connect)
    report = _watch(endpoint, config, args.listen_s)
    if args.json:
        print(json.dumps(to_json(report), indent=2))
    else:
        print(format_report(report))
    return 0


def _watch(endpoint: str, config: zenoh.Config, listen_s: float) -> StatusReport:
    """Listen on ``endpoint`` for ``listen_s`` seconds; the StatusReport of what came."""
    import threading
    import time

    from services.cli.router_client import open_client
    from shared.contract import keys
    from shared.line_status import StatusCollector

    session = open_client(endpoint, config)

    collector = StatusCollector()
    lock = threading.Lock()

    def on_message(sample: zenoh.Sample) -> None:
        payload = sample.payload.to_bytes()
        with lock:
            collector.message(str(sample.key_expr), payload, time.time_ns())

    with session:
        started = time.monotonic()
        subscriber = session.declare_subscriber(keys.ALL_STATION_TOPICS, on_message)
        try:
            time.sleep(listen_s)
            replies = session.liveliness().get(
                keys.health_key("*", "*"), timeout=LIVELINESS_TIMEOUT_S
            )
            for reply in replies:
                if reply.ok is not None:
                    with lock:
                        collector.alive(str(reply.ok.key_expr))
        finally:
            subscriber.undeclare()
        listened_s = time.monotonic() - started
        with lock:
            return collector.report(endpoint, round(listened_s, 2), time.time_ns())
