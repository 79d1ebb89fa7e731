"""What the served stations put on zenoh for the server, handed to its asyncio loop.

A subscriber per station and channel (never a wildcard over stations: another
station's messages are not this server's): ``boltwatch/<st>/results``
(:class:`~shared.contract.TighteningResult`), ``cycles`` (a multi-spindle
station's :class:`~shared.contract.CycleResult`), ``wear/alert``, ``quality/alert``
(the recorder's) and ``alarms`` (a controller bridge's). Each decoded message
goes into a thread-safe queue (zenoh calls back on its own threads); the loop
takes them with :meth:`LineInbox.next`. A payload that does not decode, or
names another station, is counted and logged (once, then at most every 10 s)
and passed over.
"""

from __future__ import annotations

import logging
import queue
from collections.abc import Sequence
from typing import Any

import zenoh

from shared.contract import (
    ControllerAlarm,
    CycleResult,
    QualityAlert,
    TighteningResult,
    WearAlert,
    channels,
    decode,
    keys,
)
from shared.errors import InputError
from shared.runtime import RateLimitedLog, ServiceSkeleton

LOG = logging.getLogger(__name__)

LineMessage = TighteningResult | CycleResult | WearAlert | QualityAlert | ControllerAlarm
#: the channels heard, by topic
CHANNELS: dict[str, channels.Channel[Any]] = {
    channel.topic: channel
    for channel in (
        channels.RESULTS,
        channels.CYCLES,
        channels.WEAR_ALERT,
        channels.QUALITY_ALERT,
        channels.ALARMS,
    )
}


class LineInbox:
    """Subscriptions through ``skeleton`` (undeclared when it stops) and their queue."""

    def __init__(self, skeleton: ServiceSkeleton, stations: Sequence[str]) -> None:
        self._queue: queue.SimpleQueue[LineMessage] = queue.SimpleQueue()
        self._log_bad = RateLimitedLog(LOG)
        self.bad_payloads = 0
        for station in stations:
            for channel in CHANNELS.values():
                skeleton.subscriber(channel.key(station), self._on_sample)

    def _on_sample(self, sample: zenoh.Sample) -> None:
        station, topic = keys.split_key(str(sample.key_expr))
        try:
            message = decode(CHANNELS[topic].message_type, sample.payload.to_bytes())
            if message.station != station:
                raise InputError(f"a {topic} message of {message.station!r} on {station!r}'s key")
        except InputError as err:
            self.bad_payloads += 1
            self._log_bad("ignored a bad %s message (#%d): %s", topic, self.bad_payloads, err)
            return
        self._queue.put(message)

    def next(self) -> LineMessage | None:
        """The next message heard, or None when there is none now."""
        try:
            return self._queue.get_nowait()
        except queue.Empty:
            return None
