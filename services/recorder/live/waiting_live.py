"""Live messages a spool's hole is not ready for yet, kept in memory until it is.

While a hole of a station's spool is being filled with what the station sends
again, live messages of the run that began inside it are deferred
(:mod:`.spool_order`): not filed, not acknowledged. They are also kept here,
up to :data:`MAX_BYTES` per spool, so that the hole files them as soon as it
reaches them, instead of waiting for the station to send each again (which it
does, and which stays the way when this memory is full or the recorder
restarts). Without this, a hole would trail the live messages by the
station's resend delay for as long as nothing new starts. A run's records
(its summary, result, a controller's result: small) are kept past
:data:`MAX_BYTES`, up to :data:`MAX_RECORDS` of them: a station whose spool
lost them too (its disk was full) still has them recorded and counted.
"""

from __future__ import annotations

import heapq
from typing import Final, Generic, TypeVar

#: kept at most per spool: about a minute of an edge station's batches
MAX_BYTES: Final = 32 * 1024 * 1024
#: a run's records kept past MAX_BYTES per spool (a few kB each: days of a station's runs)
MAX_RECORDS: Final = 10_000

MessageT = TypeVar("MessageT")


class WaitingLive(Generic[MessageT]):
    """Deferred live messages of one spool, by number."""

    def __init__(self, max_bytes: int = MAX_BYTES, max_records: int = MAX_RECORDS) -> None:
        self._max_bytes = max_bytes
        self._max_records = max_records
        self._messages: dict[int, tuple[MessageT, int]] = {}
        self._numbers: list[int] = []  # a heap of the keys
        self._records: set[int] = set()  # numbers of run records kept past the bytes
        self.bytes = 0
        self.full = 0  # messages not kept: the memory was full (the station sends them again)

    def __len__(self) -> int:
        return len(self._messages)

    def keep(self, seq: int, message: MessageT, size: int, record: bool = False) -> None:
        """Keep message ``seq`` of ``size`` bytes (``record``: a run's record, kept past
        :data:`MAX_BYTES` too)."""
        if seq in self._messages:
            return
        if self.bytes + size > self._max_bytes:
            if not record or len(self._records) >= self._max_records:
                self.full += 1
                return
            self._records.add(seq)
        self._messages[seq] = (message, size)
        heapq.heappush(self._numbers, seq)
        self.bytes += size

    def held(self, first: int, last: int) -> list[int]:
        """The numbers from ``first`` to ``last`` kept here, in order."""
        return sorted(seq for seq in self._messages if first <= seq <= last)

    def take(self, next_expected: int) -> MessageT | None:
        """The message numbered ``next_expected`` (those below it are filed or gone:
        forgotten); None when it is not here."""
        while self._numbers and self._numbers[0] < next_expected:
            self._forget(heapq.heappop(self._numbers))
        if not self._numbers or self._numbers[0] != next_expected:
            return None
        heapq.heappop(self._numbers)
        message, _ = self._forget(next_expected)
        return message

    def _forget(self, seq: int) -> tuple[MessageT, int]:
        message, size = self._messages.pop(seq)
        self._records.discard(seq)
        self.bytes -= size
        return message, size
