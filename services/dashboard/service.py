"""``boltwatch serve dashboard --config STATION... [--listen HOST:PORT]``: the line's page.

Loads the station files (the stations shown, in their order; the first
file's ``[zenoh]`` names the router, reached as that file's services reach
it, with its TLS files; their results stores are where the part search looks,
:func:`~.part_search.stores_of`), opens one zenoh session, feeds a
:class:`~.line_board.LineBoard` (:class:`~.board_feed.BoardFeed`) and serves
the page (:mod:`.web_app`) until SIGINT/SIGTERM. It meets the line's
services on zenoh only.
"""

from __future__ import annotations

import argparse
import logging
import time
from collections.abc import AsyncIterator

from aiohttp import web

from services.dashboard.board_feed import BoardFeed
from services.dashboard.line_board import LineBoard, StationSetting
from services.dashboard.part_search import PartSearch, stores_of
from services.dashboard.web_app import Listeners, make_app
from shared.config import load_any_line
from shared.runtime import open_session

LOG = logging.getLogger(__name__)

#: seconds the server waits for open streams at a stop (they are told to end first)
SHUTDOWN_TIMEOUT_S = 2.0


def main(args: argparse.Namespace) -> int:
    stations = load_any_line(args.config)
    settings = [
        StationSetting(
            station.station_id,
            station.config.recorder.wear_service_threshold,
            station.config.station.place,
        )
        for station in stations
    ]
    board = LineBoard(settings, time.time_ns())
    search = PartSearch(stores_of(stations))
    listeners = Listeners()
    host, port = args.listen

    with open_session(stations[0].config.zenoh) as session:

        async def feed(_app: web.Application) -> AsyncIterator[None]:
            board_feed = BoardFeed(session, board, listeners.changed)
            LOG.info("the line's page of %s: http://%s:%d/", ", ".join(board.stations), host, port)
            LOG.info("part search in %s", ", ".join(search.stores))
            yield
            board_feed.close()

        app = make_app(board, listeners, search)
        app.cleanup_ctx.append(feed)
        web.run_app(
            app,
            host=host,
            port=port,
            shutdown_timeout=SHUTDOWN_TIMEOUT_S,
            print=None,
            access_log=None,
        )
    return 0
