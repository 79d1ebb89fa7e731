"""Publishing on zenoh without waiting: one queue and one thread of its own per station.

The acquisition's CAN thread is the station's stop path: between two frames
it may not wait on anything, and a zenoh ``put`` with blocking congestion
control waits whenever the link to the router is congested (and it always
costs an encode and a call into zenoh). So the CAN thread only appends
``(topic, message)`` to a queue (:meth:`QueuedPublisher.publish`, a fraction
of a microsecond); this publisher's thread encodes and puts, in order. One
queue per station keeps the order of everything the station publishes: a
run's ``done`` never overtakes its last samples, its events never overtake
the samples they were found in.

The queue holds at most :data:`CAPACITY` messages (about 50 s of a station at
1 kHz): a router that takes nothing for that long loses the overflow,
counted (:attr:`QueuedPublisher.dropped`), instead of the station's memory.
Each topic gets its publisher once, with its QoS (:data:`PublisherQos`).

With ``batch_samples`` (an edge station: nobody on the line decides on its
samples), what is published on ``samples`` goes out in batches on
``sample_batches`` instead (:mod:`shared.sample_batching`): the thread keeps
the batch in progress, publishes it when due and before any other message,
so the order above holds for batches too. Each sample goes toward the line
once, on one of the two channels.
"""

from __future__ import annotations

import logging
import queue
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import zenoh

from shared import keys
from shared.codec import encode
from shared.sample_batching import SampleBatching

LOG = logging.getLogger(__name__)

CAPACITY = 50_000


@dataclass(frozen=True, slots=True)
class PublisherQos:
    """How one topic is published (zenoh's options)."""

    priority: zenoh.Priority = field(default_factory=lambda: zenoh.Priority.DATA)
    express: bool = False  # no batching: latency-critical
    congestion_control: zenoh.CongestionControl = field(
        default_factory=lambda: zenoh.CongestionControl.BLOCK
    )


#: a station's topics and their QoS: samples and run states share one priority, so a
#: run's ``done`` never overtakes its samples; a decision is REAL_TIME
STATION_QOS: Mapping[str, PublisherQos] = {
    keys.SAMPLES: PublisherQos(express=True),
    keys.SAMPLE_BATCHES: PublisherQos(express=True),
    keys.TOOL: PublisherQos(express=True),
    keys.BUS: PublisherQos(),
    keys.DECISION: PublisherQos(priority=zenoh.Priority.REAL_TIME, express=True),
    keys.EVENTS: PublisherQos(),
    keys.INTENSITY: PublisherQos(),
    keys.RUNS: PublisherQos(),
}

_STOP = object()


class QueuedPublisher:
    """Publishes a station's messages from a thread of its own, in the order given."""

    def __init__(
        self,
        session: zenoh.Session,
        station_id: str,
        qos: Mapping[str, PublisherQos] = STATION_QOS,
        capacity: int = CAPACITY,
        batch_samples: bool = False,
    ) -> None:
        """``batch_samples``: samples go out in batches on ``sample_batches``, not one by one."""
        self._session = session
        self._station_id = station_id
        self._qos = qos
        self._capacity = capacity
        self._queue: queue.SimpleQueue[Any] = queue.SimpleQueue()
        self._publishers: dict[str, zenoh.Publisher] = {}
        self._batching = SampleBatching(station_id) if batch_samples else None
        self.dropped = 0  # messages the full queue could not take
        self.failed = 0  # puts zenoh refused (a closing session)
        self._thread = threading.Thread(target=self._run, name=f"publish-{station_id}", daemon=True)
        self._thread.start()

    def publish(self, topic: str, message: object) -> None:
        """Queue ``message`` for ``boltwatch/<station>/<topic>``; never waits."""
        if self._queue.qsize() >= self._capacity:
            self.dropped += 1
            if self.dropped in (1, 100) or self.dropped % 10_000 == 0:
                LOG.error("zenoh takes nothing: %d messages dropped so far", self.dropped)
            return
        self._queue.put((topic, message))

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
                if type(item) is tuple and item[0] == keys.SAMPLES:
                    for batch in batching.add(item[1], time.monotonic()):
                        self._put(keys.SAMPLE_BATCHES, batch)
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
            self._put(keys.SAMPLE_BATCHES, batch)

    def _put(self, topic: str, message: object) -> None:
        try:
            self._publisher(topic).put(encode(message))
        except Exception as err:  # a closing session, a message that does not encode
            self.failed += 1  # counted, and the thread goes on: one message, not all
            if self.failed in (1, 100) or self.failed % 10_000 == 0:
                LOG.error("%s not published (#%d): %s", topic, self.failed, err)

    def _publisher(self, topic: str) -> zenoh.Publisher:
        publisher = self._publishers.get(topic)
        if publisher is None:
            qos = self._qos.get(topic, PublisherQos())
            publisher = self._session.declare_publisher(
                keys.station_key(self._station_id, topic),
                priority=qos.priority,
                express=qos.express,
                congestion_control=qos.congestion_control,
            )
            self._publishers[topic] = publisher
        return publisher
