"""Options of ``boltwatch serve predictor`` (light: imported for ``--help``)."""

from __future__ import annotations

import argparse


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The predictor needs only the station file (``--config``, added by ``serve``)."""
    parser.epilog = (
        "Subscribes to boltwatch/<station>/samples and /tool, publishes /events, "
        "/intensity, /decision and /runs."
    )
