"""Options of ``boltwatch serve rig`` (light imports only: ``--help`` must be fast)."""

from __future__ import annotations

import argparse


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--controller",
        choices=("can", "openprotocol"),
        default="can",
        help="can: tool controller and sensors on the station's CAN bus (default); "
        "openprotocol: an Open Protocol controller, a TCP server on the [openprotocol] "
        "section's host:port",
    )
    parser.add_argument(
        "--runs",
        type=int,
        default=None,
        help="tighten N joints, then exit 0 (default: until SIGINT/SIGTERM)",
    )
    parser.add_argument(
        "--program", type=int, default=None, help="program id (default: the first program)"
    )
    parser.add_argument(
        "--first-run-id",
        type=int,
        default=None,
        help="RunId of the first run, +1 per run (default: the current Unix time in seconds); "
        "with --controller openprotocol the first tightening id (default: one past the "
        "last the simulated controller numbered, kept in the recordings folder)",
    )
    parser.add_argument(
        "--seed",
        type=int,
        default=None,
        help="seed of the first run, +1 per run (default: [rig] seed, else a fresh one)",
    )
    parser.add_argument(
        "--wait-for-integrator",
        action="store_true",
        help="openprotocol: the first tightening waits until an integrator subscribes to "
        "results (an operator waiting for the line); later ones keep the tool's own pace",
    )
