"""The tightenings between the controller and the line: in order, once, each with its curves.

Results (0061 live, 0065 fetched) and curves (0900) arrive in any order; the
line gets each tightening once, in tightening-id order, so that the
**watermark** (every id up to it is published: :mod:`.published_ids`) is all
a restarted bridge needs to know. Here, pure (no socket, no zenoh; the clock
is passed in, monotonic seconds):

- a result whose id is at or below the watermark, or pending already, is a
  **repeat** (the controller sent it again): acknowledged by the caller,
  counted, not published;
- a result is **ready** when it is the next id (watermark + 1) and its torque
  and angle curves are here, or traces are not subscribed, or it was fetched
  (0065: no curve comes for an old result), or its curves have not come
  within ``trace_timeout_s`` of it (published without samples, counted);
- ids between the watermark and a newer result (a link that was down, a
  bridge that was stopped) are **missing**: the caller fetches each with 0064;
  one the controller cannot give (0004: unknown id; a refused 0065) is given
  up (counted by the caller) and the watermark passes it;
- at most :data:`MAX_FILL` ids are fetched after one gap: a controller keeps a
  bounded store of results, and a bridge coming back after weeks should not
  ask for every tightening since; older ids are given up, logged;
- a curve whose result was published already, or whose result has not come
  within ``trace_timeout_s``, is dropped and counted (``traces_without_result``).
"""

from __future__ import annotations

import logging
from collections.abc import Iterator
from dataclasses import dataclass, field, replace

from services.openprotocol.controller_tightening import Curve, ResultFigures, Tightening

LOG = logging.getLogger(__name__)

#: the most ids fetched to fill one gap (older ones are given up, logged)
MAX_FILL = 1000


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
    _results: dict[int, _Waiting] = field(default_factory=dict)
    _curves: dict[int, tuple[dict[str, Curve], float]] = field(default_factory=dict)
    _done: set[int] = field(default_factory=set)

    # -- in ---------------------------------------------------------------------------

    def result(self, figures: ResultFigures, now_s: float) -> bool:
        """Take a result; False when it is a repeat (published or pending already)."""
        tightening_id = figures.tightening_id
        if tightening_id <= self.watermark or tightening_id in self._results:
            return False
        if tightening_id in self._done:
            return False
        curves, _ = self._curves.pop(tightening_id, ({}, now_s))
        self._results[tightening_id] = _Waiting(
            Tightening(figures, curves.get("torque"), curves.get("angle")), now_s
        )
        self.newest = max(self.newest, tightening_id)
        return True

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
        first = self.watermark + 1
        if self.newest - first + 1 > MAX_FILL:
            skipped = self.newest - MAX_FILL - first + 1
            LOG.error(
                "ids %d to %d are more than %d results back: not fetched, given up",
                first,
                first + skipped - 1,
                MAX_FILL,
            )
            # in one step, not id by id: a first connect may find ids counting from billions
            self.watermark = first + skipped - 1
            passed = {done for done in self._done if done <= self.watermark}
            self.given_up += skipped - len(passed)  # those were given up (counted) already
            self._done -= passed
            self._advance()
            first = self.watermark + 1
        return [
            tightening_id
            for tightening_id in range(first, self.newest + 1)
            if tightening_id not in self._results and tightening_id not in self._done
        ]

    def give_up(self, tightening_id: int) -> None:
        """The controller cannot give ``tightening_id``: the watermark passes it."""
        if tightening_id <= self.watermark or tightening_id in self._done:
            return
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
            del self._results[self.watermark + 1]
            self.watermark += 1
            self._advance()
            yield tightening

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

    def _advance(self) -> None:
        while self.watermark + 1 in self._done:
            self._done.discard(self.watermark + 1)
            self.watermark += 1
