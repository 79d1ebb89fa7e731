"""A station's store and forward: keep what it puts toward the line, send again what was lost.

Everything the station's publisher puts toward the line goes into its
:class:`~shared.spool.spool_file.SpoolFile` first and gets a ``seq``; the put
carries ``<source>:<spool id>:<seq>`` in its attachment. The line's recorder answers once
a second with a :class:`~shared.contract.SpoolAck`: what it has on disk. What
it has is deleted here; what it lacks (a cut cable, a recorder that was down,
a restart of this station's service) is sent again, oldest first, at most
``drain_messages_per_s`` a second so that a line of stations coming back at
once does not bury the recorder, beside the live messages, which go on as
ever. Only messages older than ``resend_after_s`` are sent again (the
recorder acknowledges once a second), and only while acknowledgements come
(a recorder that is not there hears nothing).

The spool is bounded (``max_bytes``, its messages as stored): past it the
oldest samples go first, then the oldest other messages; a run's result and
summary never. What is dropped is counted in the file (across restarts) and
in :class:`~shared.contract.SpoolStats`.

Used by one thread (the station's publisher): :meth:`record`, :meth:`tick`,
:meth:`stats`; :meth:`on_ack` is called from zenoh's receive thread.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from typing import Any, Final

from shared.contract import (
    ControllerResult,
    RunSummary,
    Sample,
    SampleBatch,
    SpoolAck,
    SpoolStats,
    TighteningResult,
)
from shared.spool.seq_ranges import SeqRanges
from shared.spool.spool_file import (
    COMMIT_INTERVAL_S,
    COMMIT_ROWS,
    KIND_OTHER,
    KIND_RECORDS,
    KIND_SAMPLES,
    Spooled,
    SpoolFile,
)

LOG = logging.getLogger(__name__)

#: an acknowledgement older than this: the recorder is not reachable, nothing is sent again
ACK_FRESH_S: Final = 5.0
#: messages dropped at once when the spool is past its bound
DROP_CHUNK: Final = 200
_RECORDS = (TighteningResult, RunSummary, ControllerResult)


def kind_of(message: Any) -> tuple[int, int | None, int]:
    """(kind, run id, samples) of a message as the spool keeps it."""
    if type(message) is SampleBatch:
        run_id = message.samples[0].run_id if message.samples else None
        return KIND_SAMPLES, run_id, len(message.samples)
    if type(message) is Sample:
        return KIND_SAMPLES, message.run_id, 1
    run_id = getattr(message, "run_id", None)
    return (KIND_RECORDS if isinstance(message, _RECORDS) else KIND_OTHER), run_id, 0


class StationSpool:
    """One station's spool for one source (the service that publishes toward the line)."""

    def __init__(
        self,
        station: str,
        source: str,
        spool: SpoolFile,
        max_bytes: int,
        drain_messages_per_s: float,
        resend_after_s: float,
        clock_ns: Callable[[], int] = time.time_ns,
        monotonic: Callable[[], float] = time.monotonic,
    ) -> None:
        self.station = station
        self.source = source
        self._file = spool
        self._max_bytes = max_bytes
        self._rate = drain_messages_per_s
        self._resend_after_ns = round(resend_after_s * 1e9)
        self._clock_ns = clock_ns
        self._monotonic = monotonic
        self._lock = threading.Lock()
        self._ack: SpoolAck | None = None
        self._ack_at_s = -1e9
        self._acked = SeqRanges()  # applied to the file already
        self._cursor = 0  # the resend pass is past this seq
        self._pass_ended_s = -1e9
        self._tokens = 0.0
        self._tokens_at_s = monotonic()
        self._committed_at_s = monotonic()
        self.resent = 0
        self._resent_last_s: list[float] = []
        self.dropped_samples = spool.counter("dropped_samples")
        self.dropped_messages = spool.counter("dropped_messages")
        self._dropped_samples_at_start = self.dropped_samples

    @property
    def spool_id(self) -> int:
        return self._file.spool_id

    @property
    def samples_dropped_here(self) -> int:
        """Samples this process dropped to keep the bound (never to reach the line)."""
        return self.dropped_samples - self._dropped_samples_at_start

    # -- the publisher's thread ----------------------------------------------------------

    def record(self, topic: str, payload: bytes, message: Any) -> int:
        """Keep a message about to be put; its seq (for the put's attachment)."""
        kind, run_id, samples = kind_of(message)
        seq = self._file.append(topic, payload, kind, run_id, samples, self._clock_ns())
        if self._file.uncommitted >= COMMIT_ROWS:
            self._commit()
        return seq

    def tick(self) -> list[Spooled]:
        """Commit what is due, forget what the recorder has, keep the bound; the messages to
        send again now (their budget spent)."""
        now_s = self._monotonic()
        if now_s - self._committed_at_s >= COMMIT_INTERVAL_S:
            self._commit()
        with self._lock:
            ack, ack_at_s = self._ack, self._ack_at_s
        if ack is not None:
            self._apply(ack)
        self._keep_bound()
        if ack is None or now_s - ack_at_s > ACK_FRESH_S:
            return []  # the recorder does not answer: sending again would be lost again
        return self._resends(now_s, ack)

    def close(self) -> None:
        self._file.close()

    # -- zenoh's receive thread ----------------------------------------------------------

    def on_ack(self, ack: SpoolAck) -> None:
        """The recorder's latest acknowledgement of this source."""
        if (ack.station, ack.source, ack.spool_id) != (self.station, self.source, self.spool_id):
            return
        with self._lock:
            self._ack = ack
            self._ack_at_s = self._monotonic()

    # -- what it says ---------------------------------------------------------------------

    def stats(self) -> SpoolStats:
        depth = self._file.depth()
        now_s = self._monotonic()
        self._resent_last_s = [t for t in self._resent_last_s if now_s - t <= 1.0]
        with self._lock:
            acknowledged = self._ack.time_ns if self._ack is not None else None
        return SpoolStats(
            station=self.station,
            source=self.source,
            spool_id=self.spool_id,
            time_ns=self._clock_ns(),
            messages=depth.messages,
            samples=depth.samples,
            runs=depth.runs,
            bytes=depth.file_bytes,
            max_bytes=self._max_bytes,
            oldest_seq=depth.oldest_seq,
            head_seq=self._file.head_seq,
            oldest_run_id=depth.oldest_run_id,
            oldest_ns=depth.oldest_ns,
            resent=self.resent,
            resend_rate=float(len(self._resent_last_s)),
            dropped_samples=self.dropped_samples,
            dropped_messages=self.dropped_messages,
            acknowledged_ns=acknowledged,
        )

    # -- pieces ---------------------------------------------------------------------------

    def _commit(self) -> None:
        self._file.commit()
        self._committed_at_s = self._monotonic()

    def _apply(self, ack: SpoolAck) -> None:
        """Delete what the recorder has and was not deleted yet."""
        held = SeqRanges([(1, ack.through)] if ack.through else [])
        for seq_range in ack.ranges:
            held.add_range(seq_range.first, seq_range.last)
        new = [part for first, last in held for part in _without(first, last, self._acked)]
        if new:
            self._file.delete(new)
            for first, last in new:
                self._acked.add_range(first, last)

    def _keep_bound(self) -> None:
        """Past ``max_bytes``: the oldest samples go, then the oldest others; never records."""
        for kind in (KIND_SAMPLES, KIND_OTHER):
            while self._file.stored_bytes > self._max_bytes:
                messages, samples = self._file.drop_oldest(kind, DROP_CHUNK)
                if not messages:
                    break
                self.dropped_messages = self._file.add_counter("dropped_messages", messages)
                self.dropped_samples = self._file.add_counter("dropped_samples", samples)
                LOG.error(
                    "spool of %s full (%d bytes): the %d oldest %s dropped (%d samples so far)",
                    self.station,
                    self._max_bytes,
                    messages,
                    "batches of samples" if kind == KIND_SAMPLES else "messages",
                    self.dropped_samples,
                )

    def _resends(self, now_s: float, ack: SpoolAck) -> list[Spooled]:
        self._tokens = min(self._rate, self._tokens + (now_s - self._tokens_at_s) * self._rate)
        self._tokens_at_s = now_s
        budget = int(self._tokens)
        if budget < 1 or now_s - self._pass_ended_s < self._resend_after_ns / 1e9:
            return []
        self._cursor = max(self._cursor, ack.through)
        due = self._file.after(
            self._cursor, budget, self._clock_ns() - self._resend_after_ns, self._acked
        )
        if not due:  # a whole pass sent: the next waits for the acknowledgements of this one
            self._cursor = 0
            self._pass_ended_s = now_s
            return []
        self._cursor = due[-1].seq
        self._tokens -= len(due)
        self.resent += len(due)
        self._resent_last_s.extend([now_s] * len(due))
        return due


def _without(first: int, last: int, held: SeqRanges) -> list[tuple[int, int]]:
    """The parts of ``first``..``last`` not in ``held``."""
    parts = []
    start = first
    for held_first, held_last in held:
        if held_last < start:
            continue
        if held_first > last:
            break
        if held_first > start:
            parts.append((start, held_first - 1))
        start = max(start, held_last + 1)
    if start <= last:
        parts.append((start, last))
    return parts
