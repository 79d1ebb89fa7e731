"""The part at a station when its predictor starts: asked of the line, in the background.

zenoh keeps no last value for a late subscriber: a predictor that starts (an
acquisition restarted with its edge predictor, a line predictor restarted)
would know the part at its station only at the next scan, and name none in the
runs before it. The line's recorder keeps each station's last scan (across its
own restart) and answers a query of ``boltwatch/<st>/part`` with it
(``services/recorder/last_parts.py``; an error reply: it knows none).

So at start a thread of its own asks the line for each served station's part:
never the CAN thread, never the start-up, which goes on at once. A line that
does not answer (its router out of reach, its recorder down) is asked again
every :data:`ASK_PERIOD_S` until it answers, a scan of the station is heard (a
scan wins: its part is the newer), or the service stops (the query in
progress is cancelled). The answer becomes the station's part as ``restored``
(:meth:`~services.predictor.station_runs.StationRuns.restore_part`): the part
the line last heard of, which is stale when another part arrived while the
station was down and its scan never reached the line.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Mapping

import zenoh

from services.predictor.station_runs import StationRuns
from shared.contract import channels
from shared.errors import InputError

LOG = logging.getLogger(__name__)

#: how often a line that did not answer is asked again (seconds)
ASK_PERIOD_S = 2.0
#: how long one query waits for the line's answer (seconds)
QUERY_TIMEOUT_S = 2.0


class PartAtStart:
    """Asks the line for the part at each of ``stations`` until each is answered or scanned."""

    def __init__(self, session: zenoh.Session, stations: Mapping[str, StationRuns]) -> None:
        self._session = session
        self._waiting = dict(stations)  # not answered yet; changed by the thread only
        self._closed = threading.Event()
        self._cancel = zenoh.CancellationToken()
        self._thread = threading.Thread(target=self._ask, name="part-at-start", daemon=True)
        self._thread.start()

    @property
    def waiting(self) -> list[str]:
        """The stations whose part the line has not answered (and no scan was heard)."""
        return list(self._waiting)

    def close(self) -> None:
        """Stop asking (a query in progress is cancelled)."""
        self._closed.set()
        self._cancel.cancel()
        self._thread.join(timeout=QUERY_TIMEOUT_S + 1.0)

    def _ask(self) -> None:
        while self._waiting:
            for station_id, runs in list(self._waiting.items()):
                if self._closed.is_set():
                    return
                if runs.part_scanned or self._answered(station_id, runs):
                    del self._waiting[station_id]
            if self._waiting and self._closed.wait(ASK_PERIOD_S):
                return

    def _answered(self, station_id: str, runs: StationRuns) -> bool:
        """Ask the line once for ``station_id``'s part; whether it answered."""
        try:
            replies = self._session.get(
                channels.PART.key(station_id),
                timeout=QUERY_TIMEOUT_S,
                cancellation_token=self._cancel,
            )
            for reply in replies:
                if reply.ok is None:
                    error = reply.err
                    said = error.payload.to_bytes().decode(errors="replace") if error else ""
                    LOG.info("%s: the line knows no part at the station (%s)", station_id, said)
                    return True
                scan = runs.served.decode_part(reply.ok.payload.to_bytes())
                if scan.station != station_id:
                    raise InputError(f"it names station {scan.station}")
                runs.restore_part(scan)
                return True
        except InputError as err:  # the line's answer is no part scan: not asked again
            LOG.error("%s: the line's answer for its part refused: %s", station_id, err)
            return True
        except zenoh.ZError as err:  # the session is closing
            LOG.debug("%s: the line not asked for its part: %s", station_id, err)
        return False
