"""The recorder's inbox: everything on the line, taken on zenoh's receive thread, filed in batches.

One subscriber per key expression (the recorder's: one per station it
serves, ``boltwatch/<st>/**``) whose callback runs on zenoh's receive
thread (``indirect=False``) and only appends ``(key, payload, receive time,
attachment)`` to a pending list. The recorder's worker takes the whole list at once
(:meth:`LineInbox.take`, every few milliseconds) and files it: one
hand-over per batch instead of one per message (a ``FifoChannel`` read with
a blocking ``recv()``; measured side by side with ``bench_line_inbox.py
--variants recorder recorder-at-before``: ``docs/explanation/design.md``,
"Receive threads and inboxes").
The disk stays off the receive thread: a flush that waits for ``fsync``
holds the worker, not zenoh.

Nothing is dropped here. When :data:`MAX_PENDING` messages wait (the worker
is that far behind), the callback waits for room, and zenoh's receive thread
with it: zenoh reads no further, back-pressure goes to the router as with a
full FIFO (the acquisition publishes samples with BLOCK). Messages that
arrive after :meth:`LineInbox.close` are counted, not kept.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Sequence

import zenoh

from shared.runtime import keep_thread_state

#: (zenoh key, payload, receive time in ns, attachment) of one message
Message = tuple[str, bytes, int, bytes | None]

#: messages waiting before the receive thread waits too: 2 s of 50 stations at 1 kHz
MAX_PENDING = 100_000


class LineInbox:
    """Callback subscribers on ``key_exprs`` that keep what they receive for :meth:`take`."""

    def __init__(
        self,
        session: zenoh.Session,
        key_exprs: str | Sequence[str],
        max_pending: int = MAX_PENDING,
    ):
        self._max_pending = max_pending
        self._pending: list[Message] = []
        self._lock = threading.Lock()
        self._room = threading.Condition(self._lock)
        self._woken = threading.Event()
        self._closed = False
        #: messages that arrived after close() (not kept)
        self.after_close = 0
        #: times the receive thread waited because MAX_PENDING messages were waiting
        self.full_waits = 0
        wanted = [key_exprs] if isinstance(key_exprs, str) else list(key_exprs)
        self._subscribers = [
            session.declare_subscriber(
                key_expr, zenoh.handlers.Callback(self._deliver, indirect=False)
            )
            for key_expr in wanted
        ]

    def _deliver(self, sample: zenoh.Sample) -> None:
        keep_thread_state()
        attachment = sample.attachment
        message = (
            str(sample.key_expr),
            sample.payload.to_bytes(),
            time.time_ns(),
            None if attachment is None else attachment.to_bytes(),
        )
        with self._lock:
            if len(self._pending) >= self._max_pending and not self._closed:
                self.full_waits += 1
                while len(self._pending) >= self._max_pending and not self._closed:
                    self._room.wait()
            if self._closed:
                self.after_close += 1
                return
            self._pending.append(message)

    def take(self, timeout_s: float) -> list[Message]:
        """Every message received since the last take, oldest first, after waiting
        ``timeout_s`` (less once :meth:`wake` was called)."""
        if timeout_s > 0:
            self._woken.wait(timeout_s)
        with self._lock:
            taken, self._pending = self._pending, []
            self._room.notify_all()
        return taken

    def wake(self) -> None:
        """Make :meth:`take` return at once, now and from now on (the service is stopping)."""
        self._woken.set()

    def close(self) -> None:
        """Stop keeping messages and undeclare the subscriber; what was received stays for
        a last :meth:`take`. Safe to call twice.

        Closed first, then undeclared: a callback waiting for room wakes and returns
        (counted in :attr:`after_close`), so it never holds up the undeclare, and
        once ``close`` returns nothing more is appended (the lock is the barrier:
        zenoh's ``undeclare`` does not wait for a callback in progress).
        """
        with self._lock:
            if self._closed:
                return
            self._closed = True
            self._room.notify_all()
        for subscriber in self._subscribers:
            with contextlib.suppress(zenoh.ZError):  # the session is already closed
                subscriber.undeclare()
