"""Keeps the wear ledger up to date from RunSummaries and alerts when a tool is due.

After each new run the tool's intensity since its last service is compared
with ``recorder.wear_service_threshold``; at or above it a :class:`WearAlert`
is published on ``boltwatch/<station>/wear/alert`` after every run until the
tool is serviced (and logged once per crossing).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from services.recorder.wear_ledger import ToolWear, WearLedger
from shared import keys
from shared.messages import RunSummary

LOG = logging.getLogger(__name__)

ALERT_TOPIC = f"{keys.WEAR}/alert"


@dataclass(frozen=True, slots=True)
class WearAlert:
    """A tool has taken its service threshold of vibration intensity since its last service."""

    station: str
    tool_id: int
    time_ns: int
    intensity_since_service: float  # Σ I_process of the runs since the last service (eq. 69)
    threshold: float
    runs_since_service: int
    last_service_ns: int | None


class WearWatch:
    """Feed RunSummaries into the ledger; call ``alert`` when a tool is due for service."""

    def __init__(
        self,
        ledger_file: Path,
        threshold: float | None,
        alert: Callable[[WearAlert], None],
    ) -> None:
        self._ledger = WearLedger(ledger_file)
        self._threshold = threshold
        self._alert = alert
        self._due: set[int] = set()
        self.counted = 0
        self.repeated = 0

    def on_summary(self, summary: RunSummary, now_ns: int) -> ToolWear | None:
        """Count the run (once); the tool's new line, or None for a repeated summary."""
        if not self._ledger.add_run(summary, now_ns):
            self.repeated += 1
            LOG.debug("run %s/%d already in the ledger", summary.station, summary.run_id)
            return None
        self.counted += 1
        wear = self._ledger.tool(summary.tool_id)
        if self._threshold is None:
            return wear
        if wear.intensity_since_service >= self._threshold:
            if wear.tool_id not in self._due:
                LOG.warning(
                    "tool %d is due for service: intensity %.3g since last service "
                    "(threshold %.3g, %d runs)",
                    wear.tool_id,
                    wear.intensity_since_service,
                    self._threshold,
                    wear.runs_since_service,
                )
                self._due.add(wear.tool_id)
            self._alert(
                WearAlert(
                    station=summary.station,
                    tool_id=wear.tool_id,
                    time_ns=now_ns,
                    intensity_since_service=wear.intensity_since_service,
                    threshold=self._threshold,
                    runs_since_service=wear.runs_since_service,
                    last_service_ns=wear.last_service_ns,
                )
            )
        else:
            self._due.discard(wear.tool_id)
        return wear

    def close(self) -> None:
        self._ledger.close()
