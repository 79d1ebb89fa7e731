"""Which tightenings a question asks for: :class:`ResultsQuery` as SQL, newest first.

Every criterion is optional and they all hold together: a part id, stations,
a run id (with one station: a tightening by the table's primary key), a plant,
a line, a program, a tool, a range of end times (``since`` included, ``until``
not), a verdict (OK or NOK only), a spindle. Each but the verdict and the spindle
is a column with an index in front
(:mod:`.results_schema`), so a part's tightenings are found by the index of
``part_id`` however large the store. :func:`time_ns_of`: a moment as the
nanoseconds the bounds are.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from typing import Any

#: rows a query gives when it says nothing (``results`` prints the newest)
DEFAULT_LIMIT = 100
_EPOCH = datetime(1970, 1, 1, tzinfo=UTC)


def time_ns_of(moment: datetime) -> int:
    """``moment`` (aware) in nanoseconds since 1970, exactly (a datetime holds microseconds;
    ``timestamp() * 1e9``, a float of seconds, holds about a quarter of a microsecond): what
    a range's bounds are compared with, by the store and by the files alike."""
    return (moment - _EPOCH) // timedelta(microseconds=1) * 1000


@dataclass(frozen=True, slots=True)
class ResultsQuery:
    part_id: str | None = None
    stations: Sequence[str] = ()  # any of them; empty: every station
    run_id: int | None = None  # with one station: a tightening by the store's key
    plant: str | None = None
    line: str | None = None
    program_id: int | None = None
    tool_id: int | None = None
    since_ns: int | None = None  # the run ended at or after
    until_ns: int | None = None  # the run ended before
    verdict: str | None = None  # "OK" or "NOK": those only
    spindle: int | None = None  # a multi-spindle station's spindle: its runs only
    limit: int | None = DEFAULT_LIMIT  # None: every row
    oldest_first: bool = False

    def where(self) -> tuple[str, list[Any]]:
        """The WHERE clause (``""``: none) and its parameters, ``?`` for each."""
        terms: list[str] = []
        parameters: list[Any] = []

        def term(sql: str, *values: Any) -> None:
            terms.append(sql)
            parameters.extend(values)

        if self.part_id is not None:
            term("part_id = ?", self.part_id)
        if self.stations:
            term(f"station IN ({', '.join('?' * len(self.stations))})", *self.stations)
        if self.run_id is not None:
            term("run_id = ?", self.run_id)
        if self.plant is not None:
            term("plant = ?", self.plant)
        if self.line is not None:
            term("line = ?", self.line)
        if self.program_id is not None:
            term("program_id = ?", self.program_id)
        if self.tool_id is not None:
            term("tool_id = ?", self.tool_id)
        if self.since_ns is not None:
            term("ended_ns >= ?", self.since_ns)
        if self.until_ns is not None:
            term("ended_ns < ?", self.until_ns)
        if self.verdict is not None:
            term("result = ?", self.verdict)
        if self.spindle is not None:
            term("spindle = ?", self.spindle)
        return (" WHERE " + " AND ".join(terms) if terms else ""), parameters

    def order(self) -> str:
        """ORDER BY and LIMIT (newest first unless ``oldest_first``)."""
        direction = "ASC" if self.oldest_first else "DESC"
        order = f" ORDER BY ended_ns {direction}, station {direction}, run_id {direction}"
        return order + (f" LIMIT {int(self.limit)}" if self.limit is not None else "")
