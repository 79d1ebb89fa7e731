"""A multi-spindle controller's cycles: each one's common result, once its spindles are known.

A multi-spindle system (a Power Focus sync master, a PowerMACS station) says
each spindle's tightening (0061 with its channel and the cycle's sync
tightening id: published as a run of its own by :mod:`.tightening_flow`) and,
after the cycle, its common status (0091) and result (0101). The bridge
publishes one :class:`~shared.contract.CycleResult` per cycle (source
``controller``, the controller's own verdict: its sync overall status), naming
the run of each spindle of the cycle (spindle: the channel id, as the
spindle's tightening names it). A cycle waits until every spindle it lists
has its tightening published (their curves come after them), at most
``wait_s`` (then it goes with the runs known: a spindle whose tightening was
not published has no run id, its verdict the controller's). The first of
0091 and 0101 of a sync id makes the cycle (both subscribed: one result); a
sync id made once is not made again (kept for the last :data:`CYCLES_KEPT`:
the id wraps at 65535).
"""

from __future__ import annotations

import logging
import time
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass

from shared.contract import CycleResult, CycleSpindle, TighteningResult
from shared.openprotocol import MultiSpindleResult, MultiSpindleStatus

LOG = logging.getLogger(__name__)

#: spindles' tightenings and cycles made, remembered (a day of a busy station is less)
CYCLES_KEPT = 1000


@dataclass
class _Cycle:
    """A cycle the controller said, waiting for its spindles' runs."""

    time_ns: int
    ok: bool
    spindles: list[tuple[int, bool]]  # (spindle: its channel, OK)
    part_id: str | None
    program_id: int | None
    since_s: float


class ControllerCycles:
    """One station's cycles, from its controller's 0091 / 0101 to ``cycles``."""

    def __init__(
        self,
        station: str,
        publish: Callable[[object], None],
        wait_s: float,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._station = station
        self._publish = publish
        self._wait_s = wait_s
        self._clock = clock
        #: (sync id, spindle) -> the spindle's published result
        self._runs: OrderedDict[tuple[int, int], TighteningResult] = OrderedDict()
        self._waiting: dict[int, _Cycle] = {}
        self._made: OrderedDict[int, None] = OrderedDict()
        self.cycles = 0  # published

    def on_tightening(self, result: TighteningResult) -> None:
        """A spindle's tightening was published (a result with a sync id and a spindle)."""
        if result.sync_id is None or result.spindle is None:
            return
        self._runs[(result.sync_id, result.spindle)] = result
        while len(self._runs) > CYCLES_KEPT * 4:
            self._runs.popitem(last=False)

    def on_status(self, message: MultiSpindleStatus, time_ns: int) -> None:
        """A 0091: the cycle's common status and each spindle's."""
        spindles = [(s.channel_id, s.ok) for s in message.spindles]
        self._said(message.sync_tightening_id, _Cycle(time_ns, message.ok, spindles, None, None, 0))

    def on_result(self, message: MultiSpindleResult, time_ns: int) -> None:
        """A 0101: the cycle's common result and each spindle's."""
        spindles = [(s.channel_id, s.ok) for s in message.spindles]
        cycle = _Cycle(
            time_ns, message.ok, spindles, message.vin.strip() or None, message.pset_id, 0
        )
        self._said(message.sync_tightening_id, cycle)

    def _said(self, sync_id: int, cycle: _Cycle) -> None:
        if sync_id in self._made or sync_id in self._waiting:
            return  # its 0091 and its 0101: one cycle
        cycle.since_s = self._clock()
        self._waiting[sync_id] = cycle

    def publish_ready(self) -> None:
        """The cycles whose spindles' runs are all published, or that waited long enough."""
        now_s = self._clock()
        for sync_id, cycle in list(self._waiting.items()):
            runs = [self._runs.get((sync_id, spindle)) for spindle, _ in cycle.spindles]
            if any(run is None for run in runs) and now_s - cycle.since_s < self._wait_s:
                continue
            del self._waiting[sync_id]
            self._made[sync_id] = None
            while len(self._made) > CYCLES_KEPT:
                self._made.popitem(last=False)
            self._publish(self._cycle_result(sync_id, cycle, runs))
            self.cycles += 1

    def _cycle_result(
        self, sync_id: int, cycle: _Cycle, runs: list[TighteningResult | None]
    ) -> CycleResult:
        known = [run for run in runs if run is not None]
        reasons = []
        members = []
        for (spindle, ok), run in zip(cycle.spindles, runs, strict=True):
            members.append(
                CycleSpindle(spindle, run.run_id if run else None, "OK" if ok else "NOK")
            )
            if not ok:
                reasons.append(f"spindle {spindle} NOK")
            if run is None:
                LOG.warning(
                    "%s cycle %d: spindle %d's tightening not published: its run is not named",
                    self._station,
                    sync_id,
                    spindle,
                )
        part = cycle.part_id or next((run.part_id for run in known if run.part_id), None)
        program = cycle.program_id
        if program is None:
            program = known[0].program_id if known else 0
        return CycleResult(
            station=self._station,
            sync_id=sync_id,
            time_ns=max([cycle.time_ns, *(run.time_ns for run in known)]),
            part_id=part,
            program_id=program,
            result="OK" if cycle.ok else "NOK",
            nok_reasons="; ".join(reasons) if not cycle.ok else "",
            source="controller",
            spindles=members,
        )
