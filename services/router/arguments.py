"""Command-line options of ``boltwatch serve router``."""

from __future__ import annotations

import argparse


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--listen",
        action="append",
        default=None,
        metavar="ENDPOINT",
        help="endpoint to listen on, repeatable (default: tcp/127.0.0.1:7447; "
        "tcp/0.0.0.0:7447 to serve a line)",
    )
