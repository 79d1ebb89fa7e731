"""Command-line options of ``boltwatch serve openprotocol`` (the station file says the rest)."""

from __future__ import annotations

import argparse

from shared.option_types import seconds


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--stats-interval-s",
        type=seconds,
        default=1.0,
        help="how often the bridge's counters go out on boltwatch/<station>/openprotocol "
        "(default 1 s)",
    )
    parser.add_argument(
        "--trace-timeout-s",
        type=seconds,
        default=3.0,
        help="how long a result waits for its torque and angle curves (MID 0900) before it "
        "is published without samples, and a curve for its result (default 3 s)",
    )
