"""A multi-spindle cycle's common result from its spindles' results. Pure.

A multi-spindle system tightens the bolts of one part in one synchronised
cycle; each spindle's run has its own :class:`TighteningResult`, and the part
is OK only when every spindle is (as every multi-spindle controller says it,
Open Protocol's "sync overall status"). :func:`cycle_result` judges one cycle
from the results that came; a spindle whose result never came makes it NOK
("spindle 4 no result"). :class:`CycleTally` collects the results of a
station's cycles as they come (by sync id) and gives each cycle's
:class:`CycleResult` once its last spindle's result is known, or, incomplete,
when a run of another cycle starts (cycles of one system never overlap: a run
that never ended must not hold the part's result back for ever).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping

from shared.contract import CycleResult, CycleSpindle, TighteningResult, ToolState
from shared.quality.verdict import cut_text

LOG = logging.getLogger(__name__)


def cycle_result(
    station: str, sync_id: int, spindles: int, results: Mapping[int, TighteningResult]
) -> CycleResult:
    """The common result of cycle ``sync_id`` of ``spindles`` spindles, from the results of
    its spindles that came (``results``, by spindle number)."""
    reasons: list[str] = []
    members: list[CycleSpindle] = []
    for spindle in range(1, max(spindles, *results, 1) + 1):
        result = results.get(spindle)
        if result is None:
            members.append(CycleSpindle(spindle, None, None))
            reasons.append(f"spindle {spindle} no result")
            continue
        members.append(CycleSpindle(spindle, result.run_id, result.result))
        if result.result != "OK":
            reasons.append(
                f"spindle {spindle} NOK"
                + (f" ({result.nok_reasons})" if result.nok_reasons else "")
            )
    came = [results[k] for k in sorted(results)]
    first = came[0] if came else None
    return CycleResult(
        station=station,
        sync_id=sync_id,
        time_ns=max((r.time_ns for r in came), default=0),
        part_id=next((r.part_id for r in came if r.part_id is not None), None),
        program_id=first.program_id if first is not None else 0,
        result="NOK" if reasons else "OK",
        nok_reasons=cut_text("; ".join(reasons)),
        source=first.source if first is not None else "predictor",
        spindles=members,
    )


class CycleTally:
    """The cycles of one station under way, their spindles' results as they come."""

    def __init__(self, station: str, spindles: int) -> None:
        """``spindles``: the station's (a cycle is complete with that many results)."""
        self.station = station
        self.spindles = spindles
        self._open: dict[int, dict[int, TighteningResult]] = {}  # sync id -> spindle -> result

    def on_start(self, state: ToolState) -> list[CycleResult]:
        """A spindle's run starts: its cycle is open; the cycles of other sync ids still open
        are over, whatever came of them (incomplete: NOK)."""
        if state.sync_id is None:
            return []
        over = [sync_id for sync_id in self._open if sync_id != state.sync_id]
        self._open.setdefault(state.sync_id, {})
        return [self._close(sync_id) for sync_id in over]

    def on_result(self, result: TighteningResult) -> CycleResult | None:
        """A spindle's result; its cycle's common result when it was the last to come."""
        if result.sync_id is None or result.spindle is None:
            return None
        came = self._open.setdefault(result.sync_id, {})
        came[result.spindle] = result
        if len(came) < self.spindles:
            return None
        return self._close(result.sync_id)

    def _close(self, sync_id: int) -> CycleResult:
        came = self._open.pop(sync_id)
        cycle = cycle_result(self.station, sync_id, self.spindles, came)
        if len(came) < self.spindles:
            LOG.warning(
                "%s cycle %d ended with %d of %d spindles' results: %s",
                self.station,
                sync_id,
                len(came),
                self.spindles,
                cycle.nok_reasons,
            )
        return cycle
