"""The ResultIds a station's joining system has served, the newest of them only. Pure.

A result comes again when a station's spool sends what the recorder had not
acknowledged, or when the server's start replays the stores' newest results
beside the live ones: :class:`ServedResults` says whether a ResultId was served,
so each result is one event and one variable. It keeps the newest
:data:`SERVED_IDS_KEPT` ids, oldest forgotten first: a server that runs for a
year holds a bounded set (at a result a second, about 28 hours of a station's
results), where a set of every id grew for as long as it ran.
"""

from __future__ import annotations

from collections import OrderedDict

#: the ResultIds a station keeps as served (about 100 bytes each)
SERVED_IDS_KEPT = 100_000


class ServedResults:
    """The newest ResultIds served of one station."""

    def __init__(self, kept: int = SERVED_IDS_KEPT) -> None:
        if kept < 1:
            raise ValueError(f"kept is {kept}, expected at least 1")
        self._kept = kept
        self._ids: OrderedDict[str, None] = OrderedDict()

    def first_time(self, result_id: str) -> bool:
        """Whether ``result_id`` is served for the first time (then it counts as served)."""
        if result_id in self._ids:
            return False
        self._ids[result_id] = None
        while len(self._ids) > self._kept:
            self._ids.popitem(last=False)
        return True

    def __len__(self) -> int:
        return len(self._ids)
