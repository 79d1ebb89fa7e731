"""Command-line options of ``boltwatch serve opcua`` (light: no heavy imports)."""

from __future__ import annotations

import argparse
from pathlib import Path
from urllib.parse import urlsplit

DEFAULT_LISTEN = "opc.tcp://127.0.0.1:4840"


def opc_tcp_url(text: str) -> str:
    """``opc.tcp://HOST:PORT`` as given; argparse's error otherwise."""
    parts = urlsplit(text)
    try:
        port = parts.port
    except ValueError:
        port = None
    if parts.scheme != "opc.tcp" or not parts.hostname or port is None or not 1 <= port <= 65535:
        raise argparse.ArgumentTypeError(
            f"expected opc.tcp://HOST:PORT with a port from 1 to 65535, e.g. {DEFAULT_LISTEN} "
            f"(got {text!r})"
        )
    return text


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The stations come from their files (``--config``); the endpoint and its security here."""
    parser.epilog = (
        "An OPC UA server for industrial joining (OPC 40450-1 IJT Base, OPC 40451-1 "
        "Tightening): one joining system per station, each tightening result of "
        "boltwatch/<station>/results as a JoiningResultDataType in its ResultManagement "
        "and a result-ready event; the newest results of the results store at start; "
        "ResultManagement's methods give any stored result with its trace (the "
        "recording's samples) and the ids a filter matches; the tools of the wear "
        "ledger with their counters in AssetManagement. "
        "Default security: Basic256Sha256 sign and encrypt with --certificate, "
        "--private-key and --trusted-clients, and a user name and password of --users for "
        "every session (docs/how-to/opcua.md). The OPC UA models "
        "come from `make opcua-nodesets` (npm)."
    )
    parser.add_argument(
        "--listen",
        type=opc_tcp_url,
        default=DEFAULT_LISTEN,
        metavar="opc.tcp://HOST:PORT",
        help=f"the server's endpoint (default {DEFAULT_LISTEN}; opc.tcp://0.0.0.0:4840 in a "
        "container)",
    )
    security = parser.add_argument_group("security")
    security.add_argument(
        "--certificate",
        type=Path,
        default=None,
        metavar="FILE",
        help="the server's application instance certificate (RSA, PEM or DER; its "
        "subjectAltName URI is the server's application URI)",
    )
    security.add_argument(
        "--private-key", type=Path, default=None, metavar="FILE", help="its private key (PEM)"
    )
    security.add_argument(
        "--trusted-clients",
        type=Path,
        default=None,
        metavar="DIR",
        help="the client certificates (or their CAs) accepted, PEM or DER files",
    )
    security.add_argument(
        "--users",
        type=Path,
        default=None,
        metavar="FILE",
        help="the users (names, salted password hashes: `boltwatch opcua-user add`); every "
        "session logs in with one (not with --anonymous-read-only)",
    )
    security.add_argument(
        "--anonymous-read-only",
        action="store_true",
        help="also serve without security to anonymous clients (read only): only on a "
        "network where anyone may read the line's results; not with --users (a password "
        "could travel in clear)",
    )
