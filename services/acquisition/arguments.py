"""Command-line options of ``boltwatch serve acquisition`` (none beyond --config)."""

from __future__ import annotations

import argparse

from shared.option_types import seconds


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--stats-interval-s",
        type=seconds,
        default=1.0,
        help="how often bus counters are published on boltwatch/<station>/bus (default 1 s)",
    )
