"""The page's zenoh session, opened in the background: the page is served before it opens.

A zenoh client cannot open without its router, and a page that waits for
its router cannot say that the router is away. So the session is opened on
a thread of its own, each attempt waiting at most :data:`ATTEMPT_S` for the
router, for as long as it takes (a client's endpoints, TLS files and
reconnection from the station file's ``[zenoh]``, as before; a peer opens at
once). Meanwhile the board says the router cannot be reached; once open, the
:class:`~.board_feed.BoardFeed` feeds the board and says each window whether
the router is reached (asked, not told: no callback of zenoh's threads into
Python is left to run while the process ends).

The session stays a client: a peer that connects to its router only would
hear nothing from the stations' peers (a spooling acquisition opens as one)
through it.
"""

from __future__ import annotations

import json
import logging
import threading
import time
from collections.abc import Callable

import zenoh

from services.dashboard.board_feed import BoardFeed
from services.dashboard.line_board import LineBoard
from shared.config import ZenohSection
from shared.errors import TransportError
from shared.runtime import open_from, section_config

LOG = logging.getLogger(__name__)

#: seconds one attempt to open waits for the router
ATTEMPT_S = 2.0


class LineLink:
    """Opens the session on a thread, then feeds ``board``; :meth:`close` ends it all."""

    def __init__(
        self, section: ZenohSection, where: str, board: LineBoard, changed: Callable[[], None]
    ) -> None:
        self._section = section
        self._where = where  # the router's endpoints, in words
        self._board = board
        self._changed = changed
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self._session: zenoh.Session | None = None
        self._feed: BoardFeed | None = None
        board.router_link(False, time.time_ns())
        self._thread = threading.Thread(target=self._open, name="dashboard-zenoh", daemon=True)
        self._thread.start()

    def _config(self) -> zenoh.Config:
        config = section_config(self._section)
        if self._section.mode == "client":
            config.insert_json5("connect/timeout_ms", json.dumps(round(ATTEMPT_S * 1e3)))
        return config

    def _open(self) -> None:
        told = False
        while not self._stop.is_set():
            try:
                session = open_from(self._config())
            except TransportError as err:
                if not told:
                    LOG.warning("no zenoh router at %s yet (%s): trying again", self._where, err)
                    told = True
                self._stop.wait(ATTEMPT_S / 4)
                continue
            with self._lock:
                if self._stop.is_set():
                    session.close()
                    return
                self._session = session
                reachable = any(True for _ in session.info.transports())
                self._board.router_link(reachable, time.time_ns())
                self._feed = BoardFeed(session, self._board, self._changed)
                reached = "reached" if reachable else "not reached yet"
            LOG.info("zenoh session open; the router at %s %s", self._where, reached)
            self._changed()
            return

    def close(self) -> None:
        """Stop trying, or close the feed and the session."""
        self._stop.set()
        self._thread.join(ATTEMPT_S * 2)
        with self._lock:
            if self._feed is not None:
                self._feed.close()
            if self._session is not None:
                self._session.close()
