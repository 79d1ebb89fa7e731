"""The page's JSON replies: their headers, an error in words, a reply kept gzipped.

Every JSON reply is never cached and never read as anything but JSON
(:data:`JSON_HEADERS`). An error is ``{"errors": [one line why], ...}`` with its status
(:func:`error_reply`); a 503 says when to ask again (``Retry-After``). A run's view is
kept gzipped (:mod:`.run_cache`) and sent so to a browser, which always accepts gzip;
a client that does not gets it plain (:func:`gzip_reply`).
"""

from __future__ import annotations

import gzip
import json
from typing import Any

from aiohttp import web

#: headers of every JSON reply: never cached, never read as anything but JSON
JSON_HEADERS = {"Cache-Control": "no-store", "X-Content-Type-Options": "nosniff"}
#: gzip's level for a run's view: most of the size gone for little CPU (the view is cached)
GZIP_LEVEL = 5


def error_reply(
    status: int, text: str, retry_after_s: int | None = None, **extra: Any
) -> web.Response:
    """``{"errors": [text], **extra}`` with ``status`` (a 503 with ``Retry-After``)."""
    headers = dict(JSON_HEADERS)
    if retry_after_s is not None:
        headers["Retry-After"] = str(retry_after_s)
    return web.json_response({"errors": [text], **extra}, status=status, headers=headers)


def gzipped_json(document: Any) -> bytes:
    """``document`` as compact JSON (no NaN: ValueError), gzipped."""
    text = json.dumps(document, separators=(",", ":"), allow_nan=False)
    return gzip.compress(text.encode(), GZIP_LEVEL, mtime=0)


def gzip_reply(request: web.Request, body_gz: bytes) -> web.Response:
    """A JSON reply kept gzipped: as it is to a client that accepts gzip, else plain."""
    headers = JSON_HEADERS | {"Content-Type": "application/json", "Vary": "Accept-Encoding"}
    if "gzip" in request.headers.get("Accept-Encoding", "").lower():
        return web.Response(body=body_gz, headers=headers | {"Content-Encoding": "gzip"})
    return web.Response(body=gzip.decompress(body_gz), headers=headers)
