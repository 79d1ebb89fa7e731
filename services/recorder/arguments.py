"""Command-line options of ``boltwatch serve recorder`` (light: no heavy imports)."""

from __future__ import annotations

import argparse

from shared.option_types import port_number

DEFAULT_FOXGLOVE_HOST = "127.0.0.1"
DEFAULT_FOXGLOVE_PORT = 8765

DEFAULT_RERUN_GRPC_PORT = 9876
DEFAULT_RERUN_WEB_PORT = 9090


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Everything comes from the station file (``--config``) except the Rerun options."""
    parser.epilog = (
        "Writes one MCAP file per run under <recorder.folder>/<station>/<YYYY-MM-DD>/, "
        "a Rerun .rrd beside each (same name), and keeps the wear ledger "
        "<recorder.folder>/wear.sqlite."
    )
    rerun = parser.add_argument_group("Rerun")
    rerun.add_argument(
        "--no-rerun", action="store_true", help="write MCAP only, no .rrd beside each run file"
    )
    rerun.add_argument(
        "--rerun-serve",
        action="store_true",
        help="also stream every run live to a Rerun gRPC server "
        "(view it: rerun rerun+http://HOST:PORT/proxy)",
    )
    rerun.add_argument(
        "--rerun-web",
        action="store_true",
        help="also serve the Rerun web viewer from the installed wheel (implies --rerun-serve)",
    )
    rerun.add_argument(
        "--rerun-port",
        type=port_number,
        default=DEFAULT_RERUN_GRPC_PORT,
        help=f"gRPC port of --rerun-serve (default {DEFAULT_RERUN_GRPC_PORT})",
    )
    rerun.add_argument(
        "--rerun-web-port",
        type=port_number,
        default=DEFAULT_RERUN_WEB_PORT,
        help=f"HTTP port of --rerun-web (default {DEFAULT_RERUN_WEB_PORT})",
    )
    foxglove = parser.add_argument_group("Foxglove")
    foxglove.add_argument(
        "--foxglove-port",
        type=port_number,
        nargs="?",
        const=DEFAULT_FOXGLOVE_PORT,
        default=None,
        metavar="PORT",
        help="also serve every run live as a Foxglove WebSocket on this port "
        f"(alone: {DEFAULT_FOXGLOVE_PORT}); in Foxglove: Open connection, Foxglove WebSocket, "
        "ws://HOST:PORT; the layout: config/foxglove/boltwatch-layout.json",
    )
    foxglove.add_argument(
        "--foxglove-host",
        default=DEFAULT_FOXGLOVE_HOST,
        metavar="HOST",
        help=f"address the Foxglove WebSocket listens on (default {DEFAULT_FOXGLOVE_HOST}: this "
        "machine only; 0.0.0.0: every interface)",
    )
    parser.add_argument(
        "--view-only",
        action="store_true",
        help="a live view beside the line's recorder (with --rerun-web): no wear ledger, "
        "no wear queries, no RecorderStats; its health token is 'viewer', not 'recorder'",
    )
