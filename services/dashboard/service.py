"""``boltwatch serve dashboard --config STATION... [--listen HOST:PORT]``: the line's page.

Loads the station files (the stations shown, in their order; the first
file's ``[zenoh]`` names the router, reached as that file's services reach
it, with its TLS files; their results stores are where the part search looks,
:func:`~.part_search.stores_of`), raises its open-files limit, opens one zenoh
session in the background (:mod:`.line_link`: the page is served from the
start and says while the router cannot be reached), feeds a
:class:`~.line_board.LineBoard` (:class:`~.board_feed.BoardFeed`) and serves
the page (:mod:`.web_app`) within the bounds of :mod:`.connection_guard`
until SIGINT/SIGTERM; a run's curve is read from the recordings folders of the station
files (:mod:`.run_views`). It meets the line's services on zenoh only.
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import signal
import time
from collections.abc import AsyncIterator

from aiohttp import web

from services.dashboard.connection_guard import (
    ACCEPT_BACKLOG,
    ConnectionGuard,
    LoopFaultLog,
    connection_bound,
    handler_options,
    raise_open_files_limit,
)
from services.dashboard.line_board import LineBoard, StationSetting
from services.dashboard.line_link import LineLink
from services.dashboard.part_search import PartSearch, stores_of
from services.dashboard.run_locator import RunLocator, StationRecordings
from services.dashboard.run_views import RunViews
from services.dashboard.viewer_links import ViewerLinks
from services.dashboard.web_app import Listeners, make_app
from shared.config import load_any_line
from shared.runtime import exit_now

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
    zenoh_section = stations[0].config.zenoh
    router = ", ".join(zenoh_section.connect) or "(no connect endpoints)"
    board = LineBoard(settings, time.time_ns(), router)
    search = PartSearch(stores_of(stations))
    links = ViewerLinks(args.rerun_viewer, args.foxglove)
    views = RunViews(
        RunLocator([StationRecordings.of(station) for station in stations]),
        viewers=links.as_dict(),
    )
    listeners = Listeners()
    guard = ConnectionGuard(connection_bound(raise_open_files_limit()))
    host, port = args.listen

    async def feed(_app: web.Application) -> AsyncIterator[None]:
        link = LineLink(zenoh_section, router, board, listeners.changed)
        LOG.info("the line's page of %s: http://%s:%d/", ", ".join(board.stations), host, port)
        LOG.info(
            "part search in %s; at most %d connections at once",
            ", ".join(search.stores),
            guard.max_connections,
        )
        yield
        link.close()

    app = make_app(board, listeners, search, guard.middleware, views=views, links=links)
    app.cleanup_ctx.append(feed)
    asyncio.run(_serve(app, host, port, guard))
    exit_now(0)  # the session is closed: no finalisation for a late zenoh thread to abort


async def _serve(app: web.Application, host: str, port: int, guard: ConnectionGuard) -> None:
    """Serve ``app`` on ``host:port`` within ``guard``'s bounds until SIGINT or SIGTERM."""
    loop = asyncio.get_running_loop()
    loop.set_exception_handler(LoopFaultLog(LOG))
    stop = asyncio.Event()
    for number in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(number, stop.set)
    runner = web.AppRunner(
        app, access_log=None, shutdown_timeout=SHUTDOWN_TIMEOUT_S, **handler_options()
    )
    await runner.setup()
    assert runner.server is not None
    listening = await loop.create_server(
        guard.factory(runner.server), host, port, backlog=ACCEPT_BACKLOG, reuse_address=True
    )
    sweep = asyncio.create_task(guard.sweep())
    try:
        await stop.wait()
    finally:
        sweep.cancel()
        listening.close()
        await runner.cleanup()
