"""The recorder's live views beside its files: Rerun's viewer and a Foxglove WebSocket.

Started by ``serve recorder`` when asked for (``--rerun-serve`` / ``--rerun-web``,
``--foxglove-port``); one that cannot start is logged and the recording goes on
without it.
"""

from __future__ import annotations

import argparse
import logging
from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from services.recorder.foxglove_live.foxglove_server import FoxgloveLive
    from shared.recordings.rerun import RerunLive, RerunOptions

LOG = logging.getLogger(__name__)


def rerun_options(write_files: bool, live_url: str | None) -> RerunOptions | None:
    """What goes to Rerun; None when nothing does or (logged) when Rerun cannot be imported."""
    if not write_files and live_url is None:
        return None
    try:
        from shared.recordings.rerun import LIVE_BATCH_SAMPLES, RerunOptions
    except ImportError:
        LOG.exception("Rerun is unusable; recording MCAP only")
        return None
    if live_url is None:
        return RerunOptions(write_files=write_files)
    return RerunOptions(LIVE_BATCH_SAMPLES, live_url=live_url, write_files=write_files)


def start_rerun_live(args: argparse.Namespace) -> RerunLive | None:
    """The live Rerun server (and web viewer) when asked for; None when off or failing."""
    web = bool(getattr(args, "rerun_web", False))
    if not (web or getattr(args, "rerun_serve", False)):
        return None
    try:
        from shared.recordings.rerun import RerunLive

        return RerunLive(args.rerun_port, args.rerun_web_port if web else None)
    except Exception:
        LOG.exception("cannot start the Rerun live view; recording goes on without it")
        return None


def start_foxglove(args: argparse.Namespace, station_ids: Sequence[str]) -> FoxgloveLive | None:
    """The live Foxglove WebSocket when asked for (``--foxglove-port``); None when off or
    when it cannot listen (one line: recording goes on without it)."""
    port = getattr(args, "foxglove_port", None)
    if port is None:
        return None
    host = getattr(args, "foxglove_host", "127.0.0.1")
    try:
        from services.recorder.foxglove_live.foxglove_server import FoxgloveLive

        return FoxgloveLive(station_ids, host, port)
    except Exception as err:  # the SDK raises its own errors (address in use, bad host)
        LOG.error(
            "cannot serve Foxglove on %s:%d: %s; recording goes on without it", host, port, err
        )
        return None
