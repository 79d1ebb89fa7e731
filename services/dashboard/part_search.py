"""The page's part search: every tightening of a part in the results store, newest first;
and the line's NOK list, the newest NOK tightenings of the page's stations.

``GET /api/results?part=ID[&limit=N]`` (:mod:`.web_app`) asks
:meth:`PartSearch.find`, ``GET /api/noks[?limit=N]`` :meth:`PartSearch.noks`. The
stores searched are those of the station files the page serves (:func:`stores_of`:
``[recorder] results_database``, else ``results.sqlite`` in the recordings folder),
each distinct store once: a line whose stations record into two folders has two, and
a part's tightenings are gathered from both, newest first, at most ``limit``. A
plant's PostgreSQL holds every line's results, so a part's tightenings on other lines
show too (each row names its station and line).

Each search opens each store, asks (:class:`~shared.results.ResultsQuery`:
parameterised SQL, by the index of ``part_id``) and closes it, in a worker
thread (``asyncio.to_thread``): a slow store, or a PostgreSQL that does not
answer (up to its connect timeout of 5 s), never holds up the page's live
updates. A store that is not there or cannot be read is one line in the
reply (``errors``); what the other stores found is still shown. Nothing here
makes a store: the line's recorder does.
"""

from __future__ import annotations

import asyncio
import logging
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from shared.config import AnyStation
from shared.contract import PART_ID_CHARS
from shared.errors import StoreError
from shared.results import ResultsQuery, ResultsStore, StoredResult, StoreTarget, station_store
from shared.results.results_table import as_dict

LOG = logging.getLogger(__name__)

#: tightenings a search gives when it names no limit, and the most it may ask for
DEFAULT_LIMIT = 100
MAX_LIMIT = 1000
#: the application name a PostgreSQL store sees (its pg_stat_activity)
APPLICATION = "boltwatch serve dashboard"


class SearchRequestError(ValueError):
    """The question cannot be asked (no part id, one too long, a bad limit): one line why."""


def part_of(text: str | None) -> str:
    """The part id asked for: ``text`` without spaces at either end (a part id has none,
    a pasted one often does), 1 to :data:`~shared.contract.PART_ID_CHARS` characters."""
    part_id = (text or "").strip()
    if not part_id:
        raise SearchRequestError("type a part id (a VIN, a work piece's serial number)")
    if len(part_id) > PART_ID_CHARS:
        raise SearchRequestError(
            f"a part id has at most {PART_ID_CHARS} characters; this one has {len(part_id)}"
        )
    return part_id


def limit_of(text: str | None) -> int:
    """At most how many tightenings: ``text`` (None: :data:`DEFAULT_LIMIT`), 1 to
    :data:`MAX_LIMIT`."""
    if text is None:
        return DEFAULT_LIMIT
    digits = len(text) <= len(str(MAX_LIMIT)) and text.isascii() and text.isdigit()
    if not digits or not 1 <= int(text) <= MAX_LIMIT:
        raise SearchRequestError(f"limit: a number from 1 to {MAX_LIMIT} (got {text[:20]!r})")
    return int(text)


def stores_of(stations: Sequence[AnyStation]) -> list[StoreTarget]:
    """The distinct results stores of the station files, in their order."""
    targets: dict[str, StoreTarget] = {}
    for station in stations:
        target = station_store(station)
        targets.setdefault(str(target), target)
    return list(targets.values())


@dataclass(frozen=True, slots=True)
class _Answer:
    """What one store said: its tightenings of the part (newest first) and how many it
    holds in all, or why it could not say."""

    found: list[StoredResult]
    total: int
    error: str | None = None


class PartSearch:
    """The part search over the stores of the page's station files."""

    def __init__(self, targets: Sequence[StoreTarget]) -> None:
        self.targets = list(targets)

    @property
    def stores(self) -> list[str]:
        """The stores searched, as people read them (a PostgreSQL URL without its password)."""
        return [str(target) for target in self.targets]

    async def find(self, part_id: str, limit: int) -> dict[str, Any]:
        """Every store asked at once, each in a worker thread; the page's reply: the
        tightenings of ``part_id`` newest first (at most ``limit``), how many there are
        in all, and one line per store that could not answer. ``answered``: some store did."""
        query = ResultsQuery(part_id=part_id, limit=limit)
        return {"part_id": part_id} | await self._gathered(query, f"part {part_id!r}")

    async def noks(self, stations: Sequence[str], limit: int) -> dict[str, Any]:
        """The newest NOK tightenings of ``stations`` (the page's), as :meth:`find` gives a
        part's: the line's NOK list."""
        query = ResultsQuery(stations=list(stations), verdict="NOK", limit=limit)
        return {"stations": list(stations)} | await self._gathered(query, "NOK list")

    async def _gathered(self, query: ResultsQuery, what: str) -> dict[str, Any]:
        started_s = time.monotonic()
        answers = await asyncio.gather(
            *(asyncio.to_thread(_ask, target, query) for target in self.targets)
        )
        limit = query.limit or DEFAULT_LIMIT
        found: dict[tuple[str, int], StoredResult] = {}
        for answer in answers:
            for stored in answer.found:  # a result in two stores (copied over) shows once
                found.setdefault((stored.result.station, stored.result.run_id), stored)
        newest = sorted(
            found.values(),
            key=lambda s: (s.result.time_ns, s.result.station, s.result.run_id),
            reverse=True,
        )[:limit]
        errors = [answer.error for answer in answers if answer.error is not None]
        LOG.info(
            "%s: %d tightenings in %.0f ms%s",
            what,
            len(newest),
            (time.monotonic() - started_s) * 1000,
            "".join(f"; {error}" for error in errors),
        )
        return {
            "limit": limit,
            "total": max(len(newest), sum(answer.total for answer in answers)),
            "results": [as_dict(stored) for stored in newest],
            "stores": self.stores,
            "errors": errors,
            "answered": len(errors) < len(answers),
        }


def _ask(target: StoreTarget, query: ResultsQuery) -> _Answer:
    """One store's answer (in a worker thread: it opens, queries and closes the store)."""
    limit = query.limit
    try:
        with ResultsStore(target, create=False, application=APPLICATION) as store:
            found = store.find(query)
            total = store.count(query) if len(found) == limit else len(found)
    except StoreError as err:
        return _Answer([], 0, str(err))
    return _Answer(found, total)
