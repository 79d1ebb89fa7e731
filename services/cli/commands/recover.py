"""``boltwatch recover FILE [--out OUT]``: make a truncated recording readable again.

``.mcap`` files are read record by record (:mod:`shared.recordings.mcap.recovery`);
``.rrd`` files are copied chunk by chunk by the ``rerun`` CLI of the wheel
(:mod:`shared.recordings.rerun.rrd_recovery`).
"""

from __future__ import annotations

import argparse
from pathlib import Path

NAME = "recover"
HELP = "turn a truncated recording (.mcap or .rrd, recorder killed) into a valid file"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Copy every complete message, schema, channel and metadata record of FILE "
        "(every complete chunk of an .rrd) into a new valid file (FILE itself is never "
        "changed). A recorder killed with kill -9 loses at most its last flush interval "
        "of data."
    )
    parser.add_argument("file", type=Path, metavar="FILE", help="the damaged .mcap or .rrd file")
    parser.add_argument(
        "--out",
        type=Path,
        default=None,
        metavar="OUT",
        help="where to write the recovered file (default: FILE with .recovered.mcap/.rrd)",
    )


def run(args: argparse.Namespace) -> int:
    if args.file.suffix == ".rrd":
        from shared.recordings.rerun import recover_rrd

        print(recover_rrd(args.file, args.out).describe())
        return 0
    from shared.recordings.mcap import recover

    print(recover(args.file, args.out).describe())
    return 0
