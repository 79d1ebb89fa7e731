"""A set of sequence numbers kept as sorted, disjoint ranges: what a recorder has of a spool.

The recorder acknowledges what it has filed of a station's spool as ranges
(everything up to ``through``, then the ranges above it: live runs filed
while older ones wait to be sent again); the station deletes what is
acknowledged. Sequence numbers count from 1.
"""

from __future__ import annotations

import bisect
from collections.abc import Iterable, Iterator


class SeqRanges:
    """Sorted disjoint inclusive ranges of positive integers."""

    def __init__(self, ranges: Iterable[tuple[int, int]] = ()) -> None:
        self._starts: list[int] = []
        self._ends: list[int] = []
        for start, end in sorted(ranges):
            self.add_range(start, end)

    def __contains__(self, seq: int) -> bool:
        index = bisect.bisect_right(self._starts, seq) - 1
        return index >= 0 and seq <= self._ends[index]

    def end_of(self, seq: int) -> int:
        """The last number of the range holding ``seq`` (``seq`` - 1 when none holds it)."""
        index = bisect.bisect_right(self._starts, seq) - 1
        return self._ends[index] if index >= 0 and seq <= self._ends[index] else seq - 1

    def __iter__(self) -> Iterator[tuple[int, int]]:
        return zip(self._starts, self._ends, strict=True)

    def count(self) -> int:
        """How many numbers the ranges hold."""
        return sum(end - start + 1 for start, end in self)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, SeqRanges) and list(self) == list(other)

    __hash__ = None  # type: ignore[assignment]  # it changes: no hash

    def __repr__(self) -> str:
        return f"SeqRanges({list(self)})"

    def add(self, seq: int) -> None:
        self.add_range(seq, seq)

    def add_range(self, start: int, end: int) -> None:
        """Add ``start`` to ``end`` (inclusive), merging with the ranges they touch."""
        if end < start:
            return
        index = bisect.bisect_left(self._ends, start - 1)
        last = index
        while last < len(self._starts) and self._starts[last] <= end + 1:
            start = min(start, self._starts[last])
            end = max(end, self._ends[last])
            last += 1
        self._starts[index:last] = [start]
        self._ends[index:last] = [end]

    @property
    def through(self) -> int:
        """The highest ``n`` such that 1..n are all held (0: not even 1)."""
        if not self._starts or self._starts[0] > 1:
            return 0
        return self._ends[0]

    @property
    def highest(self) -> int:
        """The highest number held (0: none)."""
        return self._ends[-1] if self._ends else 0

    def above(self, seq: int) -> list[tuple[int, int]]:
        """The ranges (or their parts) above ``seq``."""
        return [(max(start, seq + 1), end) for start, end in self if end > seq]

    def missing(self, up_to: int) -> Iterator[tuple[int, int]]:
        """The ranges not held from 1 to ``up_to``."""
        expected = 1
        for start, end in self:
            if start > up_to:
                break
            if start > expected:
                yield expected, start - 1
            expected = end + 1
        if expected <= up_to:
            yield expected, up_to

    def as_list(self) -> list[list[int]]:
        """JSON-ready: ``[[start, end], ...]``."""
        return [[start, end] for start, end in self]
