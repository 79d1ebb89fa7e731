"""Command-line options of ``boltwatch serve recorder`` (light: no heavy imports)."""

from __future__ import annotations

import argparse


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The recorder takes everything from the station file (``--config``); nothing more."""
    parser.epilog = (
        "Writes one MCAP file per run under <recorder.folder>/<station>/<YYYY-MM-DD>/ "
        "and keeps the wear ledger <recorder.folder>/wear.sqlite."
    )
