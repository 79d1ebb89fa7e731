"""Keeps the wear ledger up to date from RunSummaries and alerts when a tool is due.

After each new run the tool's intensity since its last service is compared
with ``recorder.wear_service_threshold``; at or above it a :class:`WearAlert`
is published on ``boltwatch/<station>/wear/alert`` after every run until the
tool is serviced (and logged once per crossing).

A summary beyond what its run can carry (:mod:`.wear_bound`: negative, not
finite, more than its tool's torque limit allows, or inconsistent) is
refused: counted per station (``refused``, in RecorderStats and ``boltwatch
status``) and logged (at most one line per :data:`LOG_INTERVAL_NS`, with the
count of those not logged).

A ledger that cannot be written (disk full, read-only folder) never stops the
recorder: the summaries wait in memory, in order, and go in with the next
one that can be written (logged at ERROR when it starts failing, INFO when it
works again). SQLite's transactions keep the counted runs intact meanwhile.
"""

from __future__ import annotations

import logging
import sqlite3
from collections import Counter, deque
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from services.recorder.wear_bound import RefusedSummaryError, RunLimits, refusal
from services.recorder.wear_ledger import ToolWear, WearLedger
from shared import keys
from shared.messages import RunSummary

LOG = logging.getLogger(__name__)

ALERT_TOPIC = f"{keys.WEAR}/alert"
PENDING_LIMIT = 100_000  # summaries kept while the ledger cannot be written (days of runs)
#: At most one log line per this long about refused summaries.
LOG_INTERVAL_NS = 10_000_000_000


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
        limits: Callable[[RunSummary], RunLimits],
    ) -> None:
        self._ledger_file = ledger_file
        self._ledger: WearLedger | None = None
        self._threshold = threshold
        self._alert = alert
        self._limits = limits
        self._due: set[int] = set()
        self._pending: deque[tuple[RunSummary, int]] = deque(maxlen=PENDING_LIMIT)
        self.counted = 0
        self.repeated = 0
        self.refused: Counter[str] = Counter()  # by station
        self.ledger_errors = 0
        self.last_ledger_error: str | None = None
        self._refusal_logged_ns: int | None = None
        self._refusals_not_logged = 0

    def on_summary(self, summary: RunSummary, now_ns: int) -> ToolWear | None:
        """Count the run (once); the tool's new line, or None (repeated, refused, waiting)."""
        reason = refusal(summary, self._limits(summary))
        if reason is not None:
            self._refuse(RefusedSummaryError(summary, reason), now_ns)
            return None
        if len(self._pending) == PENDING_LIMIT:
            LOG.error("wear ledger: %d summaries waiting, dropping the oldest", PENDING_LIMIT)
        self._pending.append((summary, now_ns))
        wear = None
        while self._pending:
            try:
                wear = self._count(*self._pending[0])
            except RefusedSummaryError as err:  # its limits changed while it waited
                self._refuse(err, now_ns)
            except (sqlite3.Error, OSError) as err:
                self._failed(err)
                return None
            self._pending.popleft()
        if self.last_ledger_error is not None:
            LOG.info("wear ledger %s writable again; every waiting run counted", self._ledger_file)
            self.last_ledger_error = None
        return wear

    def _failed(self, err: Exception) -> None:
        self.ledger_errors += 1
        if self.last_ledger_error is None:
            LOG.error(
                "wear ledger %s cannot be written: %s; %d run(s) wait in memory",
                self._ledger_file,
                err,
                len(self._pending),
            )
        self.last_ledger_error = str(err)
        if self._ledger is not None:
            self._ledger.close()
            self._ledger = None  # reopened on the next summary

    def _refuse(self, err: RefusedSummaryError, now_ns: int) -> None:
        self.refused[err.summary.station] += 1
        last = self._refusal_logged_ns
        if last is not None and now_ns - last < LOG_INTERVAL_NS:
            self._refusals_not_logged += 1
            return
        more = self._refusals_not_logged
        self._refusal_logged_ns = now_ns
        self._refusals_not_logged = 0
        LOG.warning("%s%s", err, f" ({more} more refused since the last such line)" if more else "")

    def _count(self, summary: RunSummary, now_ns: int) -> ToolWear | None:
        if self._ledger is None:
            self._ledger = WearLedger(self._ledger_file)
        if not self._ledger.add_run(summary, now_ns, self._limits(summary)):
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
        if self._pending:
            LOG.error("wear ledger: %d run(s) could not be counted", len(self._pending))
        if self._ledger is not None:
            self._ledger.close()
