"""``boltwatch recover FILE [--out OUT]``: make a truncated recording readable again."""

from __future__ import annotations

import argparse
from pathlib import Path

NAME = "recover"
HELP = "turn a truncated MCAP recording (recorder killed) into a valid file"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Copy every complete message, schema, channel and metadata record of FILE "
        "into a new valid MCAP file (FILE itself is never changed). A recorder killed "
        "with kill -9 loses at most its last flush interval of data."
    )
    parser.add_argument("file", type=Path, metavar="FILE", help="the damaged .mcap file")
    parser.add_argument(
        "--out",
        type=Path,
        default=None,
        metavar="OUT",
        help="where to write the recovered file (default: FILE with .recovered.mcap)",
    )


def run(args: argparse.Namespace) -> int:
    from services.recorder.recovery import recover

    report = recover(args.file, args.out)
    print(report.describe())
    return 0
