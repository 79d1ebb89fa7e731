"""The tightenings between the controller and the line: in order, once, each with its curves.

Results (0061 live, 0065 fetched) and curves (0900) arrive in any order; the
line gets each tightening once, in tightening-id order, so that the
**watermark** (every id up to it is published: :mod:`.published_ids`) is all
a restarted bridge needs to know. Here, pure (no socket, no zenoh; the clock
is passed in, monotonic seconds):

- a result is told apart by its id and its **key** (time stamp, pset, torque,
  angle, verdict and part as the controller wrote them: :attr:`ResultFigures.key`).
  The same id with the same key is a **repeat** (the controller sent it
  again; so is an id whose key is not kept but comes after the oldest one
  kept, or when none is kept): acknowledged by the caller, counted, not
  published; unless the one
  taken first was fetched by id while the controller pushed it live (a
  tightening made during a catch-up): then the live one takes its place if it
  is still pending (it carries the limits and targets a 0065 lacks), and it is
  no repeat of the controller's. An id at or
  below the watermark whose key is another, or older than every key kept, is a
  **conflict**:
  the controller's ids wrapped or started again (the caller starts a new
  epoch). The keys of the last :data:`KEYS_KEPT` published ids are kept (and
  saved with the watermark), the pending ones' too;
- a result is **ready** when it is the next id (watermark + 1) and its torque
  and angle curves are here, or traces are not subscribed, or it was fetched
  (0065: no curve comes for an old result), or its curves have not come
  within ``trace_timeout_s`` of it (published without samples, counted);
- ids between the watermark and a newer result (a link that was down, a
  bridge that was stopped) are **missing**: the caller fetches each with 0064;
  one the controller cannot give (0004: unknown id; a refused 0065) is given
  up (counted by the caller) and the watermark passes it;
- at most :data:`MAX_FILL` missing ids are fetched after one gap (a controller
  keeps a bounded store of results; a bridge back after weeks should not ask
  for every tightening since): older missing ids are given up, logged. A
  result that is here already is never given up, however many came at once;
- :meth:`drain` hands out every pending result in id order, gaps given up
  (before a new epoch: nothing of the old one is left behind); the new epoch
  keeps the old one's keys, so that a controller that kept its old results
  under the ids now used again never has one of them published a second time;
- a curve whose result was published already, or whose result has not come
  within ``trace_timeout_s``, is dropped and counted (``traces_without_result``).
"""

from __future__ import annotations

import bisect
import enum
import logging
from collections import OrderedDict
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, replace

from services.openprotocol.controller_tightening import Curve, ResultFigures, Tightening

LOG = logging.getLogger(__name__)

#: the most missing ids fetched to fill one gap (older ones are given up, logged)
MAX_FILL = 1000
#: how many published ids keep their key (to tell a repeat from a wrapped or restarted id)
KEYS_KEPT = 100


class Take(enum.Enum):
    """What a result was to :meth:`PendingTightenings.result`."""

    NEW = "new"  # taken: it will be published
    REPEAT = "repeat"  # the same id and key as one published or pending: sent again
    FETCHED = "fetched"  # a live result of one fetched by id already (0065): no repeat
    CONFLICT = "conflict"  # an id published already, with another (or an unknown) key


@dataclass
class _Waiting:
    tightening: Tightening
    since_s: float


@dataclass
class PendingTightenings:
    watermark: int
    wait_for_curves: bool
    trace_timeout_s: float
    #: the newest id the controller has (0064 id 0 -> 0065); 0: unknown
    newest: int = 0
    given_up: int = 0  # ids given up (fetch failed, refused, beyond MAX_FILL)
    #: keys of the ids published last, oldest first (at most KEYS_KEPT)
    published_keys: OrderedDict[int, str] = field(default_factory=OrderedDict)
    #: the keys of the epoch before: a result of one of them is never published again
    previous_keys: dict[int, str] = field(default_factory=dict)
    #: False: resumed from a file that kept no keys (an id published cannot be told apart)
    keys_complete: bool = True
    _results: dict[int, _Waiting] = field(default_factory=dict)
    _curves: dict[int, tuple[dict[str, Curve], float]] = field(default_factory=dict)
    _done: set[int] = field(default_factory=set)
    #: every id below it that is not here is given up (a gap beyond MAX_FILL)
    _floor: int = 0
    #: the ids taken from a 0065 last (a live 0061 of one of them is no repeat)
    _fetched: OrderedDict[int, None] = field(default_factory=OrderedDict)

    @classmethod
    def resume(
        cls,
        watermark: int,
        keys: Mapping[int, str],
        wait_for_curves: bool,
        trace_timeout_s: float,
        previous_keys: Mapping[int, str] | None = None,
        *,
        new_epoch: bool = False,
    ) -> PendingTightenings:
        """Where a bridge was: its watermark and the keys of the ids it published last
        (``previous_keys``: the last ones of the epochs before, never published again;
        ``new_epoch``: an epoch that starts after ``watermark``, nothing published in it)."""
        kept = OrderedDict(sorted((i, k) for i, k in keys.items() if i <= watermark))
        return cls(
            watermark,
            wait_for_curves,
            trace_timeout_s,
            published_keys=kept,
            previous_keys=dict(previous_keys or {}),
            keys_complete=bool(kept) or watermark == 0 or new_epoch,
        )

    # -- in ---------------------------------------------------------------------------

    def result(self, figures: ResultFigures, now_s: float) -> Take:
        """Take a result: NEW, a REPEAT (not taken), or a CONFLICT (not taken)."""
        tightening_id = figures.tightening_id
        if self.previous_keys.get(tightening_id) == figures.key:
            # of the epoch before (a controller that kept its results): never again, and
            # not missing from this one
            if tightening_id > self.watermark and tightening_id not in self._results:
                self._done.add(tightening_id)
                self._advance()
            return Take.REPEAT
        waiting = self._results.get(tightening_id)
        if waiting is not None:
            earlier = waiting.tightening.result
            if earlier.key != figures.key:
                return Take.CONFLICT
            if earlier.filled and not figures.filled:  # the live one carries limits, targets
                waiting.tightening = replace(waiting.tightening, result=figures)
                return Take.FETCHED
            return Take.REPEAT
        if tightening_id <= self.watermark or tightening_id in self._done:
            known = self.published_keys.get(tightening_id)
            if known is None and self._below_the_keys(tightening_id):
                return Take.CONFLICT  # long before every id whose key is kept: ids restarted
            if known is not None and known != figures.key:
                return Take.CONFLICT
            fetched = tightening_id in self._fetched and not figures.filled
            return Take.FETCHED if fetched else Take.REPEAT
        if tightening_id < self._floor:
            self.given_up -= 1  # it was given up with its gap, and came after all
        if figures.filled:
            self._fetched[tightening_id] = None
            while len(self._fetched) > KEYS_KEPT:
                self._fetched.popitem(last=False)
        curves, _ = self._curves.pop(tightening_id, ({}, now_s))
        self._results[tightening_id] = _Waiting(
            Tightening(figures, curves.get("torque"), curves.get("angle")), now_s
        )
        self.newest = max(self.newest, tightening_id)
        return Take.NEW

    def curve(self, curve: Curve, now_s: float) -> bool:
        """Take a curve; False when its result is gone already (dropped)."""
        tightening_id = curve.tightening_id
        if tightening_id <= self.watermark or tightening_id in self._done:
            return False
        waiting = self._results.get(tightening_id)
        if waiting is not None:
            if curve.kind == "torque":
                waiting.tightening = replace(waiting.tightening, torque=curve)
            else:
                waiting.tightening = replace(waiting.tightening, angle=curve)
            return True
        curves, _ = self._curves.setdefault(tightening_id, ({}, now_s))
        curves[curve.kind] = curve
        return True

    def controller_newest(self, newest: int) -> None:
        """The controller's newest id after a (re)connect: the ids up to it are due."""
        self.newest = max(self.newest, newest)

    # -- out --------------------------------------------------------------------------

    def missing(self) -> list[int]:
        """Ids to fetch, oldest first: after the watermark, up to the newest known, that
        are neither pending nor given up. Beyond :data:`MAX_FILL` the oldest are given up."""
        first = max(self.watermark + 1, self._floor)
        known = sorted(i for i in (*self._results, *self._done) if i >= first)
        if self._missing_from(first, known) > MAX_FILL:
            start = self._fill_start(first, known)
            below = bisect.bisect_left(known, start)
            self.given_up += start - first - below  # the known ones were counted, or are here
            LOG.error(
                "ids %d to %d are more than %d results back: not fetched, given up",
                first,
                start - 1,
                MAX_FILL,
            )
            self._floor = first = start
            self._advance()
        return [
            tightening_id
            for tightening_id in range(first, self.newest + 1)
            if tightening_id not in self._results and tightening_id not in self._done
        ]

    def give_up(self, tightening_id: int) -> None:
        """The controller cannot give ``tightening_id``: the watermark passes it."""
        if tightening_id <= self.watermark or tightening_id in self._done:
            return
        if tightening_id < self._floor and tightening_id not in self._results:
            return  # given up (counted) with the gap below the floor
        self.given_up += 1
        self._done.add(tightening_id)
        self._advance()

    def ready(self, now_s: float) -> Iterator[Tightening]:
        """The tightenings to publish now, in id order; the watermark moves past each."""
        while True:
            waiting = self._results.get(self.watermark + 1)
            if waiting is None:
                return
            tightening = waiting.tightening
            waited = now_s - waiting.since_s >= self.trace_timeout_s
            if not (
                tightening.complete
                or not self.wait_for_curves
                or tightening.result.filled
                or waited
            ):
                return
            yield self._pass(tightening)

    def drain(self) -> Iterator[Tightening]:
        """Every pending result in id order, whatever it waits for; the ids between are
        given up (counted)."""
        for tightening_id in sorted(self._results):
            first = max(self.watermark + 1, self._floor)
            done = sum(1 for i in self._done if first <= i < tightening_id)
            self.given_up += max(0, tightening_id - first) - done
            self._done = {i for i in self._done if i > tightening_id}
            self.watermark = tightening_id - 1
            yield self._pass(self._results[tightening_id].tightening)

    def expired_curves(self, now_s: float) -> int:
        """Drop the curves whose result has not come within the timeout; how many."""
        expired = [
            tightening_id
            for tightening_id, (_, since_s) in self._curves.items()
            if now_s - since_s >= self.trace_timeout_s or tightening_id <= self.watermark
        ]
        count = 0
        for tightening_id in expired:
            count += len(self._curves.pop(tightening_id)[0])
        return count

    def waiting_results(self) -> int:
        return len(self._results)

    # -- pieces -----------------------------------------------------------------------

    def _pass(self, tightening: Tightening) -> Tightening:
        """``tightening`` (the next id) is handed out: the watermark moves past it."""
        tightening_id = tightening.result.tightening_id
        del self._results[tightening_id]
        self.watermark = tightening_id
        self.published_keys[tightening_id] = tightening.result.key
        while len(self.published_keys) > KEYS_KEPT:
            self.published_keys.popitem(last=False)
        self._advance()
        return tightening

    def _below_the_keys(self, tightening_id: int) -> bool:
        """Before every id whose key is kept, or none kept. Resumed from a file that kept no
        keys, it cannot tell: a repeat (never a tightening published twice)."""
        if not self.keys_complete:
            return False
        return not self.published_keys or tightening_id < next(iter(self.published_keys))

    def _missing_from(self, start: int, known: list[int]) -> int:
        """How many ids from ``start`` to the newest are neither pending nor given up."""
        if start > self.newest:
            return 0
        return self.newest - start + 1 - (len(known) - bisect.bisect_left(known, start))

    def _fill_start(self, first: int, known: list[int]) -> int:
        """The highest id from which exactly MAX_FILL ids are missing up to the newest."""
        low, high = first, self.newest  # missing_from(low) > MAX_FILL >= missing_from(newest)
        while low < high:
            middle = (low + high + 1) // 2
            if self._missing_from(middle, known) >= MAX_FILL:
                low = middle
            else:
                high = middle - 1
        return low

    def _advance(self) -> None:
        """Move the watermark past the ids given up (one by one, or below the floor in one
        step up to the next result that is here)."""
        while True:
            following = self.watermark + 1
            if following in self._done:
                self._done.discard(following)
                self.watermark = following
            elif following < self._floor and following not in self._results:
                here = (i for i in self._results if i > self.watermark)
                self.watermark = min([self._floor, *here]) - 1
                self._done = {i for i in self._done if i > self.watermark}
            else:
                return
