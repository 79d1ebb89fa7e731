"""The predictor's one FIFO: every served station's samples and tool states, in order.

Zenoh has no key expression for "these N stations and no other", and a
subscriber on ``boltwatch/*/*`` would carry every station of the line into
this process. So each served station gets its own two subscribers
(``samples`` and ``tool``) whose callbacks run on zenoh's network thread
(``indirect=False``: no thread per subscriber) and only append to one
bounded queue; ONE worker thread drains it, so all decisions still come
from a single thread in arrival order. A full queue blocks the callback (as
a zenoh FIFO channel would): nothing is dropped while the process runs.
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import zenoh

from shared import keys

QUEUE_MESSAGES = 10_000
PUT_RETRY_S = 0.5


@dataclass(frozen=True)
class Delivery:
    """One received message with the served station and topic of its subscription."""

    station_id: str
    topic: str
    payload: bytes


class StationInbox:
    """Subscribers of the served stations feeding one queue; ``receive`` blocks on it."""

    def __init__(
        self,
        session: zenoh.Session,
        station_ids: Iterable[str],
        topics: tuple[str, ...] = (keys.SAMPLES, keys.TOOL),
        max_messages: int = QUEUE_MESSAGES,
    ) -> None:
        self._queue: queue.Queue[Delivery | None] = queue.Queue(max_messages)
        self._closing = threading.Event()
        #: messages that arrived while closing (the worker had already stopped)
        self.lost_at_close = 0
        self._subscribers = [
            session.declare_subscriber(
                keys.station_key(station_id, topic),
                zenoh.handlers.Callback(self._deliver_to(station_id, topic), indirect=False),
            )
            for station_id in station_ids
            for topic in topics
        ]

    def _deliver_to(self, station_id: str, topic: str) -> Callable[[zenoh.Sample], None]:
        put = self._queue.put
        closing = self._closing

        def deliver(sample: zenoh.Sample) -> None:
            delivery = Delivery(station_id, topic, sample.payload.to_bytes())
            while not closing.is_set():
                try:
                    put(delivery, timeout=PUT_RETRY_S)
                    return
                except queue.Full:
                    continue
            self.lost_at_close += 1

        return deliver

    def receive(self) -> Delivery | None:
        """The next message, blocking; None once :meth:`wake` was called."""
        return self._queue.get()

    def wake(self) -> None:
        """Unblock :meth:`receive` (it returns None)."""
        try:
            self._queue.put_nowait(None)
        except queue.Full:
            self._closing.set()  # the worker is busy, not blocked: it sees the stop flag

    def close(self) -> None:
        """Undeclare every subscriber; a callback blocked on a full queue gives up."""
        self._closing.set()
        for subscriber in self._subscribers:
            subscriber.undeclare()
        self._subscribers.clear()
