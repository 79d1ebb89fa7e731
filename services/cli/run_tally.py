"""Which run summaries count toward ``boltwatch up --runs``: runs ``up`` saw start, once each.

Anyone on the line can put a RunSummary on ``boltwatch/<st>/runs``; a
tightening is a run the station's tool reported running (a ``ToolState``
``running`` on ``boltwatch/<st>/tool``, which the acquisition publishes once
per run id). ``up`` subscribes to both before the rigs start, and counts a
summary only for a run it saw start at that station, once however often a
summary for it comes. The others are not in the table: counted, and said
in the report (:meth:`RunTally.note`). The tool channel is read before the
summaries in each pass, so a run's start is always seen before its summary.
"""

from __future__ import annotations

import logging
from collections import Counter
from collections.abc import Iterable

from shared.contract import RunSummary, ToolState

LOG = logging.getLogger(__name__)


class RunTally:
    """The counted summaries of each station, and the ones left out."""

    def __init__(self, station_ids: Iterable[str]) -> None:
        self.summaries: dict[str, list[RunSummary]] = {station: [] for station in station_ids}
        self._started: dict[str, set[int]] = {station: set() for station in self.summaries}
        self._counted: dict[str, set[int]] = {station: set() for station in self.summaries}
        self.never_started: Counter[str] = Counter()  # by station
        self.repeated: Counter[str] = Counter()

    def tool_state(self, station: str, state: ToolState) -> None:
        """A ToolState heard on ``station``'s tool key: a run that starts is remembered."""
        if station in self._started and state.state == "running":
            self._started[station].add(state.run_id)

    def summary(self, station: str, summary: RunSummary) -> bool:
        """A RunSummary heard on ``station``'s runs key; True when it counts."""
        if station not in self.summaries:
            return False  # another station on the same router: not ours to count
        run_id = summary.run_id
        if run_id not in self._started[station] or summary.station != station:
            if not self.never_started[station]:
                LOG.warning(
                    "run summary %s/run%s not counted: no run %s started on %s's tool channel",
                    summary.station,
                    run_id,
                    run_id,
                    station,
                )
            self.never_started[station] += 1
            return False
        if run_id in self._counted[station]:
            self.repeated[station] += 1
            return False
        self._counted[station].add(run_id)
        self.summaries[station].append(summary)
        return True

    def note(self) -> str | None:
        """One line on the summaries left out, or None when none were."""
        parts = []
        for station in self.summaries:
            never, again = self.never_started[station], self.repeated[station]
            if never or again:
                parts.append(
                    f"{station}: {never} of runs never started on its tool channel, "
                    f"{again} repeated"
                )
        if not parts:
            return None
        return "run summaries not counted: " + "; ".join(parts)
