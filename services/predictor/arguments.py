"""Options of ``boltwatch serve predictor`` (light: imported for ``--help``)."""

from __future__ import annotations

import argparse


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The predictor needs only the station file (``--config``, added by ``serve``)."""
    parser.epilog = (
        "Subscribes to boltwatch/<station>/samples, /tool and /part, publishes /events, "
        "/intensity, /decision, /results and /runs (kept in the station's spool until the "
        "line's recorder has them); asks the line for each station's last part at start."
    )
