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
"""

from __future__ import annotations

import logging
import queue
import threading
import time
from collections.abc import Callable
from typing import Any

import zenoh

from shared.contract import Intensity, Sample, StickSlipEvent, channels, encode
from shared.runtime.sample_batching import SampleBatching
from shared.runtime.zenoh_session import declare_channel

LOG = logging.getLogger(__name__)

CAPACITY = 50_000

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
    ) -> None:
        """``batch_samples``: samples go out in batches on ``sample_batches``, not one by one."""
        self._session = session
        self._station_id = station_id
        self._capacity = capacity
        self._queue: queue.SimpleQueue[Any] = queue.SimpleQueue()
        self._publishers: dict[str, zenoh.Publisher] = {}
        self._batching = SampleBatching(station_id) if batch_samples else None
        self.dropped = 0  # messages the full queue could not take
        self.failed = 0  # puts zenoh refused (a closing session)
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

    def call(self, function: Callable[[], None]) -> None:
        """Run ``function`` on the publishing thread, after what is queued before it."""
        self._queue.put(function)

    def close(self) -> None:
        """Publish what is queued, then stop the thread and undeclare the publishers."""
        self._queue.put(_STOP)
        self._thread.join(timeout=10.0)
        for publisher in self._publishers.values():
            publisher.undeclare()
        self._publishers.clear()

    def _run(self) -> None:
        batching = self._batching
        while True:
            wait_s = None if batching is None else batching.wait_s(time.monotonic())
            try:
                item = self._queue.get(timeout=wait_s)
            except queue.Empty:  # the batch in progress is due and nothing else came
                self._send_batch()
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
        batch = None if self._batching is None else self._batching.take()
        if batch is not None:
            self._put(channels.SAMPLE_BATCHES, batch)

    def _put(self, channel: channels.Channel[Any], message: object) -> None:
        try:
            self._publisher(channel).put(encode(message))
        except Exception as err:  # a closing session, a message that does not encode
            self.failed += 1  # counted, and the thread goes on: one message, not all
            if self.failed in (1, 100) or self.failed % 10_000 == 0:
                LOG.error("%s not published (#%d): %s", channel.topic, self.failed, err)

    def _publisher(self, channel: channels.Channel[Any]) -> zenoh.Publisher:
        publisher = self._publishers.get(channel.topic)
        if publisher is None:
            publisher = declare_channel(self._session, channel, self._station_id)
            self._publishers[channel.topic] = publisher
        return publisher
