"""The page's web side (aiohttp): the page, its data, and its live updates.

- ``GET /``: the page (``page/index.html``), and ``GET /page/<file>`` its CSS
  and script, served from the package: nothing comes from the internet;
- ``GET /board.json``: the board now (:meth:`LineBoard.snapshot`);
- ``GET /events``: server-sent events, one ``data:`` line with the board
  each time it changed (a result, a run's end, an alert; and every window),
  at most every :data:`MIN_INTERVAL_S`; the browser's EventSource reconnects
  by itself when the server comes back;
- ``GET /api/results?part=ID[&limit=N]``: every tightening of a part in the
  results store, newest first (:mod:`.part_search`): 200 with what was found
  (and a line per store that could not answer), 503 when no store answered,
  400 when the question cannot be asked (no part id, one too long, a bad
  limit); always JSON, ``{"errors": [...]}`` saying why;
- ``GET /api/noks[?limit=N]``: the line's NOK list, the newest NOK tightenings of the
  page's stations in the results store, as the part search answers;
- ``/api/runs/...``: a run's curve, its part's runs, its program's band and its files
  (:mod:`.run_routes`), when the app is given the page's :class:`~.run_views.RunViews`.

zenoh calls :meth:`Listeners.changed` from its own threads; it wakes every
open ``/events`` stream on the event loop.
"""

from __future__ import annotations

import asyncio
import json
import logging
import time
from pathlib import Path

from aiohttp import web
from aiohttp.typedefs import Middleware

from services.dashboard.json_replies import JSON_HEADERS
from services.dashboard.line_board import LineBoard
from services.dashboard.part_search import PartSearch, SearchRequestError, limit_of, part_of
from services.dashboard.run_routes import add_run_routes
from services.dashboard.run_views import RunViews
from services.dashboard.viewer_links import ViewerLinks
from shared.runtime import RateLimitedLog

PAGE = Path(__file__).with_name("page")
#: the shortest pause between two updates of one stream (a burst of results is one update)
MIN_INTERVAL_S = 0.2
#: a comment line this often keeps proxies from closing a quiet stream
KEEP_ALIVE_S = 15.0

#: a client that went away mid-stream: one line, at most every 10 s
_GONE = RateLimitedLog(logging.getLogger(__name__), logging.INFO)

BOARD_KEY = web.AppKey("board", LineBoard)
SEARCH_KEY = web.AppKey("search", PartSearch)


class Listeners:
    """The open ``/events`` streams, each woken by a token in its queue of one."""

    def __init__(self) -> None:
        self._loop: asyncio.AbstractEventLoop | None = None
        self._queues: set[asyncio.Queue[bool]] = set()

    def bind(self, loop: asyncio.AbstractEventLoop) -> None:
        """The server's event loop (at its start)."""
        self._loop = loop

    def changed(self) -> None:
        """From any thread: the board changed (before the server runs: nobody to tell)."""
        loop = self._loop
        if loop is not None and not loop.is_closed():
            loop.call_soon_threadsafe(self._wake, True)

    def close(self) -> None:
        """On the loop: every stream ends (the server stops)."""
        self._wake(False)

    def _wake(self, more: bool) -> None:
        for queue in self._queues:
            if queue.empty():
                queue.put_nowait(more)

    def add(self) -> asyncio.Queue[bool]:
        queue: asyncio.Queue[bool] = asyncio.Queue(maxsize=1)
        self._queues.add(queue)
        return queue

    def remove(self, queue: asyncio.Queue[bool]) -> None:
        self._queues.discard(queue)


LISTENERS_KEY = web.AppKey("listeners", Listeners)


def make_app(
    board: LineBoard,
    listeners: Listeners,
    search: PartSearch,
    *middlewares: Middleware,
    views: RunViews | None = None,
    links: ViewerLinks | None = None,
) -> web.Application:
    app = web.Application(middlewares=middlewares)
    app[BOARD_KEY] = board
    app[LISTENERS_KEY] = listeners
    app[SEARCH_KEY] = search
    app.router.add_get("/", _index)
    app.router.add_get("/board.json", _board)
    app.router.add_get("/events", _events)
    app.router.add_get("/api/results", _results)
    app.router.add_get("/api/noks", _noks)
    if views is not None:
        add_run_routes(app, views, links or ViewerLinks())
    app.router.add_static("/page/", PAGE)
    app.on_startup.append(_bind_loop)
    app.on_shutdown.append(_end_streams)
    return app


async def _bind_loop(app: web.Application) -> None:
    app[LISTENERS_KEY].bind(asyncio.get_running_loop())


async def _index(_request: web.Request) -> web.FileResponse:
    return web.FileResponse(PAGE / "index.html")


async def _board(request: web.Request) -> web.Response:
    return web.json_response(request.app[BOARD_KEY].snapshot(time.time_ns()))


async def _results(request: web.Request) -> web.Response:
    try:
        part_id = part_of(request.query.get("part"))
        limit = limit_of(request.query.get("limit"))
    except SearchRequestError as err:
        return web.json_response({"errors": [str(err)]}, status=400, headers=JSON_HEADERS)
    found = await request.app[SEARCH_KEY].find(part_id, limit)
    return web.json_response(found, status=200 if found["answered"] else 503, headers=JSON_HEADERS)


async def _noks(request: web.Request) -> web.Response:
    try:
        limit = limit_of(request.query.get("limit"))
    except SearchRequestError as err:
        return web.json_response({"errors": [str(err)]}, status=400, headers=JSON_HEADERS)
    stations = request.app[BOARD_KEY].stations
    found = await request.app[SEARCH_KEY].noks(stations, limit)
    return web.json_response(found, status=200 if found["answered"] else 503, headers=JSON_HEADERS)


async def _events(request: web.Request) -> web.StreamResponse:
    board, listeners = request.app[BOARD_KEY], request.app[LISTENERS_KEY]
    response = web.StreamResponse(
        headers={"Content-Type": "text/event-stream", "Cache-Control": "no-cache"}
    )
    queue = listeners.add()
    try:
        await response.prepare(request)
        more = True
        while more:
            snapshot = json.dumps(board.snapshot(time.time_ns()))
            await response.write(f"data: {snapshot}\n\n".encode())
            await asyncio.sleep(MIN_INTERVAL_S)
            try:
                more = await asyncio.wait_for(queue.get(), KEEP_ALIVE_S)
            except TimeoutError:
                await response.write(b": still here\n\n")
    except ConnectionResetError as err:  # the browser went away (aiohttp's is one too)
        _GONE("an /events stream ended: the client went away (%s)", type(err).__name__)
    finally:
        listeners.remove(queue)
    return response


async def _end_streams(app: web.Application) -> None:
    app[LISTENERS_KEY].close()
