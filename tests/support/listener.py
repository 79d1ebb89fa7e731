"""What a test hears on zenoh: a station's messages, each decoded by its channel.

:class:`Listener` subscribes, on a session of the test, every key of a station
(``boltwatch/<station>/**``) or only the keys of some topics, decodes each
message with the codec as the type of its channel
(:func:`shared.contract.channels.by_topic`) and keeps it under its topic, in
the order heard. A key of no channel is passed over; a payload the codec
refuses is kept as it came in :attr:`Listener.refused`. ``station`` may be
``*``: every station's messages, each naming its station.

With ``samples_from_batches``, a :class:`~shared.contract.SampleBatch` is heard
as its samples, under ``samples`` (an edge station or a bridge sends its
samples in batches; a test counts them one by one as a line predictor hears
them); the batch itself is not kept.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections import defaultdict
from collections.abc import Callable, Iterable
from types import TracebackType
from typing import Any

import zenoh

from shared.contract import SampleBatch, channels, decode, keys
from shared.errors import InputError

WAIT_S = 10.0  # upper bound on waits for zenoh; tests never assert on time
POLL_S = 0.05  # how often a condition is looked at again when no message came


class Listener:
    """Every message of ``station`` heard on ``session`` (only ``topics``' when given), by
    topic, until :meth:`close` (a context manager)."""

    def __init__(
        self,
        session: zenoh.Session,
        station: str = "st1",
        topics: Iterable[str] = (),
        *,
        samples_from_batches: bool = False,
    ) -> None:
        self.station = station
        #: ``(key, payload)`` of every message its channel's type refused
        self.refused: list[tuple[str, bytes]] = []
        self._samples_from_batches = samples_from_batches
        self._messages: dict[str, list[Any]] = defaultdict(list)
        self._arrived = threading.Condition()
        expressions = [keys.station_key(station, topic) for topic in topics]
        self._subscribers = [
            session.declare_subscriber(expression, self._on_sample)
            for expression in expressions or [keys.station_key(station, "**")]
        ]

    def _on_sample(self, sample: zenoh.Sample) -> None:
        key = str(sample.key_expr)
        _, topic = keys.split_key(key)
        channel = channels.by_topic(topic)
        if channel is None:
            return
        payload = sample.payload.to_bytes()
        try:
            message = decode(channel.message_type, payload)
        except InputError:
            with self._arrived:
                self.refused.append((key, payload))
                self._arrived.notify_all()
            return
        with self._arrived:
            if self._samples_from_batches and isinstance(message, SampleBatch):
                self._messages[channels.SAMPLES.topic].extend(message.samples)
            else:
                self._messages[topic].append(message)
            self._arrived.notify_all()

    def of(self, topic: str) -> list[Any]:
        """The messages of ``topic`` heard so far, in order (a copy)."""
        with self._arrived:
            return list(self._messages[topic])

    def wait(self, condition: Callable[[], object], what: str, timeout_s: float = WAIT_S) -> None:
        """Until ``condition()`` is true, looked at as messages arrive; AssertionError naming
        ``what`` after ``timeout_s``."""
        deadline = time.monotonic() + timeout_s
        while not condition():
            left = deadline - time.monotonic()
            if left <= 0:
                raise AssertionError(f"gave up waiting for {what}")
            with self._arrived:
                self._arrived.wait(min(left, POLL_S))

    def wait_for(self, topic: str, count: int, timeout_s: float = WAIT_S) -> list[Any]:
        """The messages of ``topic`` once at least ``count`` were heard; AssertionError after
        ``timeout_s``."""
        self.wait(lambda: len(self.of(topic)) >= count, f"{count} {topic} messages", timeout_s)
        return self.of(topic)

    def close(self) -> None:
        """Undeclare the subscribers (nothing more is heard); a closed session is fine."""
        for subscriber in self._subscribers:
            with contextlib.suppress(zenoh.ZError):
                subscriber.undeclare()
        self._subscribers = []

    def __enter__(self) -> Listener:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()
