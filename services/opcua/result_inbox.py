"""The served stations' results from zenoh, handed to the server's asyncio loop.

A subscriber per station on ``boltwatch/<st>/results`` (never a wildcard over
stations: another station's results are not this server's) puts each decoded
:class:`~shared.contract.TighteningResult` into a thread-safe queue (zenoh calls
back on its own threads); the loop takes them with :meth:`ResultInbox.next`. A
payload that does not decode, or names another station, is counted and logged
(once, then at most every 10 s) and passed over.
"""

from __future__ import annotations

import logging
import queue
from collections.abc import Sequence

import zenoh

from shared.contract import TighteningResult, channels, decode, keys
from shared.errors import InputError
from shared.runtime import RateLimitedLog, ServiceSkeleton

LOG = logging.getLogger(__name__)


class ResultInbox:
    """Subscriptions through ``skeleton`` (undeclared when it stops) and their queue."""

    def __init__(self, skeleton: ServiceSkeleton, stations: Sequence[str]) -> None:
        self._queue: queue.SimpleQueue[TighteningResult] = queue.SimpleQueue()
        self._log_bad = RateLimitedLog(LOG)
        self.bad_payloads = 0
        for station in stations:
            skeleton.subscriber(channels.RESULTS.key(station), self._on_sample)

    def _on_sample(self, sample: zenoh.Sample) -> None:
        station, _topic = keys.split_key(str(sample.key_expr))
        try:
            result = decode(TighteningResult, sample.payload.to_bytes())
            if result.station != station:
                raise InputError(f"a result of {result.station!r} on {station!r}'s key")
        except InputError as err:
            self.bad_payloads += 1
            self._log_bad("ignored a bad result (#%d): %s", self.bad_payloads, err)
            return
        self._queue.put(result)

    def next(self) -> TighteningResult | None:
        """The next result heard, or None when there is none now."""
        try:
            return self._queue.get_nowait()
        except queue.Empty:
            return None
