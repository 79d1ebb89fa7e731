"""The page's routes of a run: its curve, its part's runs, its program's band, its files.

A run is ``/api/runs/<station>/<run id>`` (a station id as the station files spell it,
a run id of at most 19 digits within 64 bits):

- ``GET /api/runs/ST/RUN``: the run's view (:meth:`~.run_views.RunViews.view`);
- ``GET /api/runs/ST/RUN/part[?align=POINT]``: every tightening of its part overlaid;
- ``GET /api/runs/ST/RUN/program[?runs=N][&align=POINT]``: against its program's last N
  (2 to :data:`MAX_BAND_RUNS`, :data:`DEFAULT_BAND_RUNS` by default) OK runs at the station;
  ``align`` as ``inspect --overlay --align`` takes it (``start``, ``first-slip``,
  ``torque:NM``; ``start`` by default);
- ``GET /api/runs/ST/RUN/cycle[?align=POINT]``: a multi-spindle station's run with every
  spindle's run of its cycle overlaid, and the cycle's common result (404: a run of a
  single-spindle station);
- ``GET /api/runs/ST/RUN/files/NAME``: one of the run's files (its MCAP files, the
  ``.rrd`` beside one), as a download; an outside viewer's origin
  (:mod:`.viewer_links`) may read it across origins (and ask first: ``OPTIONS``).

Answers are JSON (the files aside): 200 with what was asked; 400 when the question
cannot be asked (not a station id or run id, a bad ``runs`` or ``align``); 404 when there
is no such run here, or its recording is not (a station the page does not serve, a run
the store and the folder do not know, a file the store names outside the station's
recordings folder or gone, a name that is not one of the run's files); 422 when its
recording cannot be read (not MCAP, no samples of the run); 503 when the page is busy
reading (``Retry-After``) or the store does not answer. ``{"errors": [one line why]}``
with ``"pending": true`` when the run's result may be on its way to the store.
"""

from __future__ import annotations

from aiohttp import web

from services.dashboard.json_replies import error_reply, gzip_reply
from services.dashboard.run_locator import RunRequestError
from services.dashboard.run_views import RunViews, download_files
from services.dashboard.viewer_links import ViewerLinks
from shared.contract import INT64_MAX, STATION_ID
from shared.errors import InputError
from shared.offline.overlay import Alignment, parse_alignment

VIEWS_KEY = web.AppKey("run_views", RunViews)
LINKS_KEY = web.AppKey("viewer_links", ViewerLinks)

RUN = "/api/runs/{station:[A-Za-z0-9_-]{1,64}}/{run:[0-9]{1,19}}"
#: a program's runs a band is made of: by default, and at most
DEFAULT_BAND_RUNS = 20
MAX_BAND_RUNS = 100
#: seconds a browser waits before it asks a busy page again
RETRY_AFTER_S = 1
#: what a file download says of itself
_FILE_HEADERS = {"Cache-Control": "no-store", "X-Content-Type-Options": "nosniff"}
#: what a viewer reading a file across origins may see of the answer
_EXPOSED = "Content-Length, Content-Range, Accept-Ranges"


def add_run_routes(app: web.Application, views: RunViews, links: ViewerLinks) -> None:
    app[VIEWS_KEY] = views
    app[LINKS_KEY] = links
    app.router.add_get(RUN, _view)
    app.router.add_get(RUN + "/part", _part)
    app.router.add_get(RUN + "/program", _band)
    app.router.add_get(RUN + "/cycle", _cycle)
    app.router.add_get(RUN + "/files/{name}", _file)
    app.router.add_route("OPTIONS", RUN + "/files/{name}", _preflight)
    app.router.add_route("*", "/api/runs{rest:.*}", _not_a_run)
    app.on_cleanup.append(_close)


async def _close(app: web.Application) -> None:
    app[VIEWS_KEY].close()


def _run_of(request: web.Request) -> tuple[str, int]:
    station = request.match_info["station"]
    run_id = int(request.match_info["run"])
    if run_id > INT64_MAX or not STATION_ID.fullmatch(station):
        raise RunRequestError(400, f"a run id is at most {INT64_MAX} (got {run_id})")
    return station, run_id


def _alignment(request: web.Request) -> Alignment:
    try:
        return parse_alignment(request.query.get("align", "start")[:40])
    except InputError as err:
        raise RunRequestError(400, str(err).replace("--align", "align")) from err


def _refused(err: RunRequestError) -> web.Response:
    if err.status == 503:
        return error_reply(503, err.text, RETRY_AFTER_S)
    return error_reply(err.status, err.text, pending=err.pending)


async def _view(request: web.Request) -> web.Response:
    try:
        body = await request.app[VIEWS_KEY].view(*_run_of(request))
    except RunRequestError as err:
        return _refused(err)
    return gzip_reply(request, body)


async def _part(request: web.Request) -> web.Response:
    try:
        station, run_id = _run_of(request)
        body = await request.app[VIEWS_KEY].part(station, run_id, _alignment(request))
    except RunRequestError as err:
        return _refused(err)
    return gzip_reply(request, body)


async def _cycle(request: web.Request) -> web.Response:
    try:
        station, run_id = _run_of(request)
        body = await request.app[VIEWS_KEY].cycle(station, run_id, _alignment(request))
    except RunRequestError as err:
        return _refused(err)
    return gzip_reply(request, body)


async def _band(request: web.Request) -> web.Response:
    try:
        station, run_id = _run_of(request)
        runs = _band_runs(request.query.get("runs"))
        views = request.app[VIEWS_KEY]
        body = await views.band(station, run_id, runs, _alignment(request))
    except RunRequestError as err:
        return _refused(err)
    return gzip_reply(request, body)


def _band_runs(text: str | None) -> int:
    if text is None:
        return DEFAULT_BAND_RUNS
    if not (text.isascii() and text.isdigit() and len(text) <= 3) or not (
        2 <= int(text) <= MAX_BAND_RUNS
    ):
        raise RunRequestError(400, f"runs: a number from 2 to {MAX_BAND_RUNS} (got {text[:20]!r})")
    return int(text)


async def _file(request: web.Request) -> web.StreamResponse:
    try:
        station, run_id = _run_of(request)
        located = await request.app[VIEWS_KEY].located(station, run_id)
    except RunRequestError as err:
        return _refused(err)
    name = request.match_info["name"]
    found = download_files(located).get(name)
    if found is None:
        names = ", ".join(download_files(located)) or "none"
        return error_reply(
            404, f"{name[:120]!r} is not a file of run {run_id} of {station} (its files: {names})"
        )
    headers = _FILE_HEADERS | {
        "Content-Type": "application/octet-stream",
        "Content-Disposition": f'attachment; filename="{name}"',
    }
    headers |= _cross_origin(request)
    return web.FileResponse(found[1], headers=headers)


async def _preflight(request: web.Request) -> web.Response:
    """A viewer's browser asking first whether it may read a file (with a Range header)."""
    allowed = _cross_origin(request)
    if not allowed:
        return error_reply(403, "only the outside viewers named at the page's start read its files")
    headers = allowed | {
        "Access-Control-Allow-Methods": "GET, HEAD",
        "Access-Control-Allow-Headers": "Range",
        "Access-Control-Max-Age": "600",
    }
    return web.Response(status=204, headers=headers)


def _cross_origin(request: web.Request) -> dict[str, str]:
    """CORS headers for an outside viewer's origin (none for any other)."""
    origin = request.headers.get("Origin")
    if not request.app[LINKS_KEY].allows(origin):
        return {}
    assert origin is not None
    return {
        "Access-Control-Allow-Origin": origin,
        "Access-Control-Expose-Headers": _EXPOSED,
        "Vary": "Origin",
    }


async def _not_a_run(request: web.Request) -> web.Response:
    return error_reply(
        400,
        "a run is asked as /api/runs/STATION/RUN[/part|/program|/cycle|/files/NAME]: a station id "
        "(letters, digits, _ and -) and a run id (digits)",
    )
