"""The page's zenoh side: one client session feeding the :class:`~.line_board.LineBoard`.

- a subscriber on ``boltwatch/<st>/**`` per station served (every channel,
  alerts below ``wear/`` too; a station of no file is not asked for);
- a window thread: every :data:`~.line_board.WINDOW_S` it looks whether the
  session reaches anyone (its router: the page says so), asks which
  liveliness tokens exist (``boltwatch/<st>/health/*``, as ``boltwatch
  status`` does) and each station's recorder for its wear (``boltwatch/<st>/wear``),
  then closes the board's window;
- the page's own liveliness token ``boltwatch/<st>/health/dashboard`` per
  station (its container health check: ``boltwatch health dashboard``).

``changed`` is called (from zenoh's threads) when the page should be redrawn.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

import zenoh

from services.dashboard.line_board import WINDOW_S, LineBoard
from shared.contract import keys
from shared.errors import InputError

LOG = logging.getLogger(__name__)

#: the page's health token (``boltwatch health dashboard``)
HEALTH = "dashboard"
QUERY_TIMEOUT_S = 1.0


class BoardFeed:
    """Subscriptions, tokens and the window thread of one session; :meth:`close` ends them."""

    def __init__(
        self, session: zenoh.Session, board: LineBoard, changed: Callable[[], None]
    ) -> None:
        self._session = session
        self._board = board
        self._changed = changed
        self._stop = threading.Event()
        self._subscribers = [
            session.declare_subscriber(keys.station_key(station, "**"), self._on_message)
            for station in board.stations
        ]
        self._tokens = [
            session.liveliness().declare_token(keys.health_key(station, HEALTH))
            for station in board.stations
        ]
        self._thread = threading.Thread(target=self._windows, name="dashboard-windows", daemon=True)
        self._thread.start()

    def _on_message(self, sample: zenoh.Sample) -> None:
        if self._board.message(str(sample.key_expr), sample.payload.to_bytes(), time.time_ns()):
            self._changed()

    def _windows(self) -> None:
        while not self._stop.wait(WINDOW_S):
            try:
                reachable = any(True for _ in self._session.info.transports())
                self._board.router_link(reachable, time.time_ns())
                self._close_window()
            except zenoh.ZError as err:  # the router is away: the next window tries again
                LOG.warning("window not closed: %s", err)
            self._changed()

    def _close_window(self) -> None:
        alive = [
            str(reply.ok.key_expr)
            for reply in self._session.liveliness().get(
                keys.health_key("*", "*"), timeout=QUERY_TIMEOUT_S
            )
            if reply.ok is not None
        ]
        self._board.close_window(alive, time.time_ns())
        for station in self._board.stations:
            self._ask_wear(station)

    def _ask_wear(self, station: str) -> None:
        replied = False
        for reply in self._session.get(
            keys.station_key(station, keys.WEAR), timeout=QUERY_TIMEOUT_S
        ):
            now_ns = time.time_ns()
            if reply.ok is None:
                reason = reply.err.payload.to_string() if reply.err is not None else "error"
                self._board.wear_failed(station, f"the recorder says: {reason}", now_ns)
                replied = True
                continue
            try:
                self._board.wear_reply(station, reply.ok.payload.to_bytes(), now_ns)
                replied = True
            except InputError as err:
                self._board.wear_failed(station, str(err), now_ns)
                replied = True
        if not replied:
            self._board.wear_failed(station, "no recorder answered", time.time_ns())

    def close(self) -> None:
        self._stop.set()
        self._thread.join(QUERY_TIMEOUT_S * 3 + WINDOW_S)
        for token in self._tokens:
            token.undeclare()
        for subscriber in self._subscribers:
            subscriber.undeclare()
