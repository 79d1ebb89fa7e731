"""Command-line options of ``boltwatch serve router``."""

from __future__ import annotations

import argparse
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--listen",
        action="append",
        default=None,
        metavar="ENDPOINT",
        help="endpoint to listen on, repeatable (default: tcp/127.0.0.1:7447; "
        "tcp/0.0.0.0:7447 to serve a line; tls/0.0.0.0:7447 with the --tls-* options)",
    )
    parser.add_argument(
        "--connect",
        action="append",
        default=None,
        metavar="ENDPOINT",
        help="another line's router to mesh with, repeatable (a plant of several lines: "
        "each line's services connect to their own router, the routers to each other; "
        "docs/how-to/line-and-plant.md). Retried for ever, so the lines may start "
        "in any order",
    )
    tls = parser.add_argument_group("TLS (mutual: every service shows a certificate)")
    tls.add_argument("--tls-root-ca", type=Path, metavar="PEM", help="the line's CA certificate")
    tls.add_argument("--tls-cert", type=Path, metavar="PEM", help="the router's certificate")
    tls.add_argument("--tls-key", type=Path, metavar="PEM", help="the router's private key")
    parser.add_argument(
        "--access-control",
        type=Path,
        metavar="JSON5",
        help="zenoh access_control section (rules, subjects, policies), e.g. "
        "config/security/access_control.json5",
    )
