"""What the recorder does with a station's spooled messages: file each once, each run whole.

A spooling station numbers every message it puts toward the line, and marks
what it sends again (``<source>:<seq>[:again]`` in the put's attachment,
:mod:`shared.spool`). Per (station, source), one :class:`SpoolOrder` says what
becomes of each numbered message (pure: no file, no zenoh):

- the next number, live: filed into the station's **live** files, as ever;
- a number filed already: **skip** (sent again before our acknowledgement
  reached the station);
- a live number past a gap (a cut cable, a recorder that was down): a
  **hole** opens from the first number missing, and the file of the run that
  was being recorded is handed to it (:meth:`RecorderService`'s work). The
  station sends the missing numbers again, oldest first; the hole files them
  in order, into that run's file and into the files of the runs that follow.
  Live messages go on meanwhile: those of a run that began inside the hole are
  **deferred** (not filed, not acknowledged: the station sends them again, and
  the hole files them in that run's one file; the recorder keeps them in
  memory meanwhile, so the hole files them as soon as it reaches them); from
  the first run that starts live after the gap, the live files go on, and
  the hole ends before it. When the hole reaches the live messages first
  (nothing was running, or the gap was short) it has **caught up**: it ends
  there and hands its open run back to the live files. Newer runs are never
  held back behind a backlog.
- a number sent again, inside a hole: filed by the hole when it is the hole's
  next, skipped below it, deferred above it (one sent again and lost again:
  the station's next pass sends it once more);
- a number sent again past everything known (the tail of a cut with nothing
  live after it): the next one goes to the live files, one past it opens a hole;
- numbers the station no longer has (dropped to keep its spool's bound, or
  lost with its disk) are **gone**: counted, and the holes pass them. A message
  sent again names the number its spool holds before it (every number between
  is gone), and the station's counters name its oldest
  (:meth:`SpoolOrder.station_has_from`). A number the recorder holds itself,
  deferred in memory (``held``), is never gone: the hole files it when it
  gets there (the station's copy was lost, the recorder's was not).

A source that starts no runs (a line predictor: its events, decisions, results
and summaries belong to the runs the station's acquisition starts) is not
**in order** (``in_order=False``): its messages are not kept in the order of
runs it does not see; each number is filed when it first comes, live or sent
again, and skipped after (the recorder puts it in the file of its run).

:attr:`SpoolOrder.filed` (every number filed, or gone) is what the recorder
acknowledges once its files are flushed, and keeps across its restarts.
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from shared.spool import SeqRanges

#: the numbers from ``first`` to ``last`` held in memory, in order (deferred live messages)
Held = Callable[[int, int], Sequence[int]]


def nothing_held(_first: int, _last: int) -> Sequence[int]:
    return ()


class Fate(enum.Enum):
    LIVE = "live"  # into the station's live files
    HOLE = "hole"  # into the files of :attr:`Routing.hole`
    SKIP = "skip"  # filed already
    DEFER = "defer"  # not now: the station sends it again


@dataclass
class Hole:
    """Numbers ``next`` to ``last`` still to be filed, in order (``last`` None: its end is
    not known yet: no run has started live since the gap)."""

    first: int
    next: int
    last: int | None = None
    #: where its messages are filed (the recorder's StationFiles of this hole)
    files: Any = None

    @property
    def complete(self) -> bool:
        return self.last is not None and self.next > self.last

    def holds(self, seq: int) -> bool:
        return self.first <= seq and (self.last is None or seq <= self.last)


@dataclass(frozen=True, slots=True)
class Routing:
    fate: Fate
    hole: Hole | None = None
    #: a hole opened with this message: the live files' open run is to be handed to it
    opened: bool = False
    #: the open hole caught up with the live messages (it ends before this one): its open
    #: run is handed back to the live files, which go on with it
    caught_up: bool = False


@dataclass
class SpoolOrder:
    """One source of one station: what is filed, and the holes still to fill."""

    filed: SeqRanges = field(default_factory=SeqRanges)
    holes: list[Hole] = field(default_factory=list)
    gone: int = 0  # numbers the station no longer had, passed
    seen: int = 0  # the highest number that came (nothing above it is ever taken as gone)
    deferred: int = 0
    skipped: int = 0
    #: its messages start runs, and are filed in order (False: each as it first comes)
    in_order: bool = True

    @classmethod
    def resumed(cls, filed: SeqRanges, gone: int = 0, in_order: bool = True) -> SpoolOrder:
        """The order of a recorder that saved what it had filed (and restarted, or failed to
        write): every number missing below the highest is a hole to fill (in order)."""
        missing = filed.missing(filed.highest) if in_order else []
        holes = [Hole(first, first, last) for first, last in missing]
        return cls(filed, holes, gone, seen=filed.highest, in_order=in_order)

    @property
    def open_hole(self) -> Hole | None:
        """The hole whose end is not known yet (live messages wait for a run to start)."""
        return next((hole for hole in self.holes if hole.last is None), None)

    @property
    def next_expected(self) -> int:
        """The number that would be filed next: the open hole's next, else one past the top."""
        opened = self.open_hole
        return opened.next if opened is not None else self.top + 1

    @property
    def top(self) -> int:
        """The highest number filed or inside a hole."""
        ends = [hole.last if hole.last is not None else hole.next - 1 for hole in self.holes]
        return max([self.filed.highest, *ends])

    def route(
        self,
        seq: int,
        run_started: bool,
        kept_before: int | None = None,
        held: Held = nothing_held,
    ) -> Routing:
        """What becomes of message ``seq`` (``run_started``: a run's start, a ToolState
        running; ``kept_before``: sent again, and the number the station's spool holds
        before it; None: live; ``held``: the numbers kept in memory, never gone)."""
        self.seen = max(self.seen, seq)
        if seq in self.filed:
            return self._skip()
        if kept_before is not None and kept_before <= self.top:
            self._gone(kept_before + 1, seq - 1, held)  # not in the spool, not filed: gone
            if seq in self.filed:
                return self._skip()
        if not self.in_order:
            return Routing(Fate.LIVE)
        hole = next((hole for hole in self.holes if hole.holds(seq)), None)
        if kept_before is not None:
            if hole is not None:
                if seq == hole.next:
                    return Routing(Fate.HOLE, hole)
                return self._skip() if seq < hole.next else self._defer()
            return self._past_everything(seq, run_started)
        opened = self.open_hole
        if opened is not None:
            if run_started and seq > opened.next:
                opened.last = seq - 1  # the first run live after the gap: the hole ends here
                return Routing(Fate.LIVE)
            if seq == opened.next:  # everything before it is filed: the hole caught up
                opened.last = seq - 1
                return Routing(Fate.LIVE, opened, caught_up=True)
            return self._defer()
        if hole is not None:  # live, but inside a hole: older than the live front
            return self._defer()
        return self._past_everything(seq, run_started)

    def filed_as(self, seq: int, routing: Routing) -> None:
        """``seq`` was filed as ``routing`` said."""
        self.filed.add(seq)
        if routing.fate is Fate.HOLE and routing.hole is not None:
            routing.hole.next = seq + 1
        for hole in self.holes:
            self._pass_filed(hole)

    def station_has_from(self, oldest_seq: int, held: Held = nothing_held) -> int:
        """The station's spool holds nothing below ``oldest_seq`` (its oldest message, or one
        past its newest when it is empty): what is not filed below it, nor ``held``, is
        gone; how many."""
        return self._gone(1, oldest_seq - 1, held)

    def completed(self) -> list[Hole]:
        """The holes filled to their end: removed (their files are the caller's to close)."""
        done = [hole for hole in self.holes if hole.complete]
        self.holes = [hole for hole in self.holes if not hole.complete]
        return done

    def _past_everything(self, seq: int, run_started: bool) -> Routing:
        top = self.top
        if seq == top + 1:
            return Routing(Fate.LIVE)
        hole = Hole(top + 1, top + 1)
        self.holes.append(hole)
        if run_started:
            hole.last = seq - 1
            return Routing(Fate.LIVE, hole, opened=True)
        self.deferred += 1
        return Routing(Fate.DEFER, hole, opened=True)

    def _gone(self, first: int, last: int, held: Held = nothing_held) -> int:
        """Numbers ``first`` to ``last`` that are not filed, nor ``held``, are gone: passed
        (the holes go past them), counted; how many. Never past :attr:`seen` (a number that
        never came may still come)."""
        last = min(last, self.seen)
        passed = 0
        for missing_first, missing_last in list(self.filed.missing(last)):
            if missing_last >= first:
                start = max(missing_first, first)
                for gone_first, gone_last in _without(start, missing_last, held):
                    passed += gone_last - gone_first + 1
                    self.filed.add_range(gone_first, gone_last)
        if passed:
            self.gone += passed
            for hole in self.holes:
                self._pass_filed(hole)
        return passed

    def _pass_filed(self, hole: Hole) -> None:
        """A hole's next passes numbers filed already (live ones the hole overlaps, gone ones)."""
        if hole.next in self.filed and (hole.last is None or hole.next <= hole.last):
            hole.next = self.filed.end_of(hole.next) + 1
            if hole.last is not None:
                hole.next = min(hole.next, hole.last + 1)

    def _defer(self) -> Routing:
        self.deferred += 1
        return Routing(Fate.DEFER)

    def _skip(self) -> Routing:
        self.skipped += 1
        return Routing(Fate.SKIP)


def _without(first: int, last: int, held: Held) -> list[tuple[int, int]]:
    """The ranges of ``first`` to ``last`` between the numbers ``held``."""
    ranges = []
    start = first
    for number in held(first, last):
        if number > start:
            ranges.append((start, number - 1))
        start = number + 1
    if start <= last:
        ranges.append((start, last))
    return ranges
