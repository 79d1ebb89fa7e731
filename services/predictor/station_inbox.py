"""The predictor's inbox: every served station's samples, tool states and part scans, one at a time.

Each served station gets its own subscribers (``samples``, ``tool`` and
``part``) whose callbacks run on zenoh's receive thread (``indirect=False``), keep that
thread's Python thread state (:func:`shared.runtime.receive_threads.keep_thread_state`)
and handle the message right there, under one lock: decisions come from one
message at a time, in arrival order, with no queue and no hand-over to a
worker, and back-pressure goes to the router. The handler may publish from
inside the callback because the predictor never subscribes, on the same
session, to a key it publishes. An exception in the handler is kept, later
messages are counted in :attr:`StationInbox.lost_after_failure`, and
:meth:`StationInbox.serve` raises it in the service's worker thread (exit
status 1). Why this shape, and the variants measured against it:
``docs/explanation/design.md``, "Receive threads and inboxes".
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable, Sequence
from typing import Protocol

import zenoh

from shared.contract import channels, keys
from shared.runtime import keep_thread_state

#: (served station id, topic, payload) -> None; called one message at a time
Handler = Callable[[str, str, bytes], None]


class Inbox(Protocol):
    """What the predictor service needs of its inbox (the benchmark compares others)."""

    def serve(self, stop: threading.Event) -> None: ...

    def wake(self) -> None: ...

    def close(self) -> None: ...


#: builds an inbox on a session for the served station ids, feeding a handler
InboxFactory = Callable[[zenoh.Session, Sequence[str], Handler], Inbox]


class StationInbox:
    """Subscribers of the served stations whose callbacks call ``handle`` under one lock."""

    #: keep each receive thread's Python thread state (see the module docstring)
    keep_thread_states = True

    def __init__(
        self,
        session: zenoh.Session,
        station_ids: Iterable[str],
        handle: Handler,
        topics: tuple[str, ...] = (
            channels.SAMPLES.topic,
            channels.TOOL.topic,
            channels.PART.topic,
        ),
    ) -> None:
        self._handle = handle
        self._lock = threading.Lock()
        self._ended = threading.Event()
        self._failure: BaseException | None = None
        self._closed = False
        #: messages that arrived after the handler had failed (not handled)
        self.lost_after_failure = 0
        self._subscribers = [
            session.declare_subscriber(
                keys.station_key(station_id, topic),
                zenoh.handlers.Callback(self._deliver_to(station_id, topic), indirect=False),
            )
            for station_id in station_ids
            for topic in topics
        ]

    def _deliver_to(self, station_id: str, topic: str) -> Callable[[zenoh.Sample], None]:
        handle = self._handle
        lock = self._lock
        keep = self.keep_thread_states

        def deliver(sample: zenoh.Sample) -> None:
            if keep:
                keep_thread_state()
            payload = sample.payload.to_bytes()
            with lock:
                if self._closed:  # shutting down: the service no longer publishes
                    return
                if self._failure is not None:
                    self.lost_after_failure += 1
                    return
                try:
                    handle(station_id, topic, payload)
                except BaseException as err:  # raised again by serve(), never swallowed
                    self._failure = err
                    self._ended.set()

        return deliver

    def serve(self, stop: threading.Event) -> None:
        """Block until ``stop`` is set (and :meth:`wake` called) or the handler failed."""
        while not stop.is_set():
            self._ended.wait()
            if self._failure is not None:
                raise self._failure
            if not stop.is_set():
                self._ended.clear()

    def wake(self) -> None:
        """Unblock :meth:`serve` (it returns once the stop flag is set)."""
        self._ended.set()

    def close(self) -> None:
        """Undeclare every subscriber, then wait for a callback in progress to finish.

        zenoh's ``undeclare`` does not wait for a running callback, so the lock
        is the barrier: once ``close`` returns no handler runs, and the service
        may undeclare its publishers and close the session.
        """
        for subscriber in self._subscribers:
            subscriber.undeclare()
        self._subscribers.clear()
        with self._lock:
            self._closed = True
