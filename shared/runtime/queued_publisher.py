"""Publishing on zenoh without waiting: one queue and one thread of its own per station.

The acquisition's CAN thread is the station's stop path: between two frames
it may not wait on anything, and a zenoh ``put`` with blocking congestion
control waits whenever the link to the router is congested (and it always
costs an encode and a call into zenoh). So the CAN thread only appends
``message`` to a queue (:meth:`QueuedPublisher.publish`, a fraction
of a microsecond); this publisher's thread encodes and puts, in order. One
queue per station keeps the order of everything the station publishes: a
run's ``done`` never overtakes its last samples, its events never overtake
the samples they were found in.

The queue holds at most :data:`CAPACITY` messages (about 50 s of a station at
1 kHz): a router that takes nothing for that long loses the overflow,
counted (:attr:`QueuedPublisher.dropped`), instead of the station's memory.
Each channel gets its publisher once, with its options (:mod:`shared.contract.channels`).

With ``batch_samples`` (an edge station: nobody on the line decides on its
samples), samples go out in batches on ``sample_batches`` instead
(:mod:`shared.runtime.sample_batching`): the thread keeps the batch in progress,
puts the events and intensities the predictor finds into it, and publishes it
when due and before any other message, so the order above holds for batches
too. Each sample, event and intensity goes toward the line once, alone or in
a batch.

With a ``spool`` (:class:`~shared.spool.StationSpool`: store and forward on the
edge box), every message is kept on disk before its put, and the put carries
its number; the thread also sends again what the line's recorder lacks
(on ``again/<topic>``, beside the live messages, at a bounded rate) and publishes the spool's
counters once a second. A spool that fails (a full disk) costs the spooling,
counted, never the live messages.
"""

from __future__ import annotations

import logging
import queue
import sqlite3
import threading
import time
from collections.abc import Callable
from typing import Any

import zenoh

from shared.config import AnyStation
from shared.contract import (
    Intensity,
    Sample,
    SpoolAck,
    StickSlipEvent,
    channels,
    decode,
    encode,
    keys,
    seq_attachment,
)
from shared.errors import ConfigError, InputError
from shared.runtime.log_limit import RateLimitedLog
from shared.runtime.sample_batching import SampleBatching
from shared.runtime.zenoh_session import declare_channel
from shared.spool import Spooled, SpoolFile, StationSpool, kind_of

LOG = logging.getLogger(__name__)

CAPACITY = 50_000
#: how often the spool commits, forgets what the recorder has and sends again (seconds)
SPOOL_TICK_S = 0.05
SPOOL_STATS_S = 1.0

_STOP = object()
#: what rides in the batch in progress (:meth:`SampleBatching.add_found`)
_FOUND = (StickSlipEvent, Intensity)


class QueuedPublisher:
    """Publishes a station's messages from a thread of its own, in the order given."""

    def __init__(
        self,
        session: zenoh.Session,
        station_id: str,
        capacity: int = CAPACITY,
        batch_samples: bool = False,
        spool: StationSpool | None = None,
        runs_at_once: int = 1,
    ) -> None:
        """``batch_samples``: samples go out in batches on ``sample_batches``, not one by one
        (``runs_at_once``: a batch in progress for each of that many runs: a multi-spindle
        station's spindles). ``spool``: keep every message until the line's recorder has it
        (closed with this)."""
        self._session = session
        self._station_id = station_id
        self._capacity = capacity
        self._queue: queue.SimpleQueue[Any] = queue.SimpleQueue()
        self._publishers: dict[str, zenoh.Publisher] = {}
        self._batching = (
            SampleBatching(station_id, runs_at_once=runs_at_once) if batch_samples else None
        )
        self.dropped = 0  # messages the full queue could not take
        self.failed = 0  # puts zenoh refused (a closing session)
        self._spool = spool
        self.spool_errors = 0  # messages put without being kept: the spool failed
        self._unkept_samples = 0  # samples among them
        self._log_spool = RateLimitedLog(LOG, logging.ERROR)
        self._spool_due_s = self._stats_due_s = time.monotonic()
        self._acks: zenoh.Subscriber[None] | None = None
        if spool is not None:
            self._acks = session.declare_subscriber(
                channels.SPOOL_ACK.key(station_id), self._on_ack
            )
        self._thread = threading.Thread(target=self._run, name=f"publish-{station_id}", daemon=True)
        self._thread.start()

    def publish(self, message: object) -> None:
        """Queue ``message`` for its channel (:mod:`shared.contract.channels`) of the station; never
        waits. KeyError for a message no channel carries."""
        if self._queue.qsize() >= self._capacity:
            self.dropped += 1
            if self.dropped in (1, 100) or self.dropped % 10_000 == 0:
                LOG.error("zenoh takes nothing: %d messages dropped so far", self.dropped)
            return
        self._queue.put((channels.of_message(message), message))

    @property
    def spooling(self) -> bool:
        """Every message is kept until the line's recorder has it (a cut loses nothing)."""
        return self._spool is not None

    @property
    def lost_samples(self) -> int:
        """Samples that will never reach the line though spooling: not kept (the spool
        failed) or dropped to keep its bound, by this process."""
        spool = self._spool
        return self._unkept_samples + (spool.samples_dropped_here if spool is not None else 0)

    def call(self, function: Callable[[], None]) -> None:
        """Run ``function`` on the publishing thread, after what is queued before it."""
        self._queue.put(function)

    def close(self) -> None:
        """Publish what is queued, then stop the thread and undeclare the publishers."""
        self._queue.put(_STOP)
        self._thread.join(timeout=10.0)
        if self._acks is not None:
            self._acks.undeclare()
            self._acks = None
        for publisher in self._publishers.values():
            publisher.undeclare()
        self._publishers.clear()
        if self._spool is not None:
            self._spool.close()

    def _run(self) -> None:
        batching = self._batching
        while True:
            now_s = time.monotonic()
            wait_s = None if batching is None else batching.wait_s(now_s)
            if self._spool is not None:
                self._spool_work(now_s)
                spool_wait_s = max(0.0, self._spool_due_s - now_s)
                wait_s = spool_wait_s if wait_s is None else min(wait_s, spool_wait_s)
            try:
                item = self._queue.get(timeout=wait_s)
            except queue.Empty:  # a batch in progress is due, or the spool's work
                if batching is not None:
                    for batch in batching.take_due(time.monotonic()):
                        self._put(channels.SAMPLE_BATCHES, batch)
                continue
            if batching is not None:
                message = item[1] if type(item) is tuple else None
                if type(message) is Sample:
                    for batch in batching.add(message, time.monotonic()):
                        self._put(channels.SAMPLE_BATCHES, batch)
                    continue
                if isinstance(message, _FOUND) and batching.add_found(message):
                    continue
                self._send_batch()  # nothing overtakes the samples queued before it
            if item is _STOP:
                return
            if callable(item):
                item()
                continue
            self._put(*item)

    def _send_batch(self) -> None:
        if self._batching is not None:
            for batch in self._batching.take_all():
                self._put(channels.SAMPLE_BATCHES, batch)

    def _put(self, channel: channels.Channel[Any], message: object) -> None:
        try:
            payload = encode(message)
            self._publisher(channel).put(payload, attachment=self._keep(channel, payload, message))
        except Exception as err:  # a closing session, a message that does not encode
            self.failed += 1  # counted, and the thread goes on: one message, not all
            if self.failed in (1, 100) or self.failed % 10_000 == 0:
                LOG.error("%s not published (#%d): %s", channel.topic, self.failed, err)

    def _keep(self, channel: channels.Channel[Any], payload: bytes, message: object) -> Any:
        """The attachment of a spooled message (None: no spool, or it failed: counted)."""
        spool = self._spool
        if spool is None:
            return None
        try:
            seq = spool.record(channel.topic, payload, message)
            return seq_attachment(spool.source, spool.spool_id, seq)
        except (sqlite3.Error, OSError) as err:
            self.spool_errors += 1
            self._unkept_samples += kind_of(message)[2]
            self._log_spool(
                "spool of %s failed (%d messages not kept): %s",
                self._station_id,
                self.spool_errors,
                err,
            )
            return None

    def _spool_work(self, now_s: float) -> None:
        """Commit, forget what the recorder has, send again what it lacks; the counters."""
        spool = self._spool
        assert spool is not None
        try:
            if now_s >= self._spool_due_s:
                self._spool_due_s = now_s + SPOOL_TICK_S
                for spooled in spool.tick():
                    self._resend(spooled)
        except (sqlite3.Error, OSError, zenoh.ZError) as err:
            self.spool_errors += 1
            self._log_spool("spool of %s: %s", self._station_id, err)
        try:  # also when the work failed: the recorder learns what the spool no longer has
            if now_s >= self._stats_due_s:
                self._stats_due_s = now_s + SPOOL_STATS_S
                self._publisher(channels.SPOOL).put(encode(spool.stats()))
        except (sqlite3.Error, OSError, zenoh.ZError) as err:
            self.spool_errors += 1
            self._log_spool("spool of %s: %s", self._station_id, err)

    def _resend(self, spooled: Spooled) -> None:
        """On ``again/<topic>``: for the line's recorder, never a live subscriber; below the
        live messages, and dropped rather than waited on when the link is congested (the
        next pass sends it again)."""
        spool = self._spool
        assert spool is not None
        self._session.put(
            keys.again_key(self._station_id, spooled.topic),
            spooled.payload,
            attachment=seq_attachment(
                spool.source, spool.spool_id, spooled.seq, spooled.kept_before
            ),
            priority=zenoh.Priority.DATA_LOW,
            congestion_control=zenoh.CongestionControl.DROP,
        )

    def _on_ack(self, sample: zenoh.Sample) -> None:
        """A recorder's acknowledgement (zenoh's receive thread)."""
        spool = self._spool
        if spool is None:
            return
        try:
            spool.on_ack(decode(SpoolAck, sample.payload.to_bytes()))
        except InputError as err:
            self._log_spool("a spool acknowledgement refused: %s", err)

    def _publisher(self, channel: channels.Channel[Any]) -> zenoh.Publisher:
        publisher = self._publishers.get(channel.topic)
        if publisher is None:
            publisher = declare_channel(self._session, channel, self._station_id)
            self._publishers[channel.topic] = publisher
        return publisher


def station_spool(station: AnyStation, source: str) -> StationSpool | None:
    """The spool of ``station``'s messages from ``source`` (its ``[spool]``); None when off.

    ``<[spool] folder>/<station>-<source>.sqlite`` on the box the service runs on."""
    section = station.config.spool
    if not section.enabled:
        return None
    path = station.spool_folder / f"{station.station_id}-{source}.sqlite"
    try:
        spool_file = SpoolFile(path)
    except (sqlite3.Error, OSError) as err:
        raise ConfigError(f"{station.path}: spool.folder: {path}: cannot be opened: {err}") from err
    return StationSpool(
        station.station_id,
        source,
        spool_file,
        section.max_bytes,
        section.drain_messages_per_s,
        section.resend_after_s,
    )
