"""Keeps the wear ledger up to date from RunSummaries and alerts when a tool is due.

What a controller says of its tool (a bridge's :class:`~shared.contract.messages.ToolData`)
goes in beside the runs (:mod:`shared.wear.wear_tool_data`); while the ledger fails the
newest of each (station, tool) waits in memory (not kept on disk at a stop: a
bridge says it again at its next connection).

After each new run the tool's intensity since its last service is compared
with ``recorder.wear_service_threshold``; at or above it a :class:`WearAlert`
is published on ``boltwatch/<station>/wear/alert`` after every run until the
tool is serviced (and logged once per crossing). Below it, the tool's service
is forecast, and a ``WearForecast`` put once per tool and horizon of
``recorder.wear_forecast_days`` it comes within (:mod:`.wear_forecasts`).

A summary beyond what its run can carry (:mod:`shared.wear.wear_bound`: negative, not
finite, more than its tool's torque limit allows, or inconsistent) is
refused: counted per station (``refused``, in RecorderStats and ``boltwatch
status``) and logged (at most one line per :data:`LOG_INTERVAL_NS`, with the
count of those not logged).

The ledger failing never stops the recorder: the summaries wait in memory,
in order, and go in when it works again. Two kinds of failure:

- it cannot be written now (disk full, read-only folder): tried again with
  every summary and every :data:`CHECK_INTERVAL_NS`;
- it is broken (:class:`~shared.wear.wear_ledger_file.BrokenLedgerError`: empty, not
  SQLite, another schema, corrupt; or the file was emptied, overwritten or
  replaced while the recorder had it open): nothing is written into it; the
  summaries wait until a person moves it aside (``boltwatch wear reset``),
  then go into the new ledger at the next check.

Either is logged at ERROR when it starts, reminded every
:data:`REMINDER_INTERVAL_NS` with the count waiting, and INFO when the
ledger works again; ``last_ledger_error`` says it to RecorderStats
(``last_error``), ``waiting`` how many runs wait. Runs still waiting when
the recorder stops are kept on disk and counted first at its next start
(:mod:`shared.wear.wear_waiting`).
"""

from __future__ import annotations

import logging
import sqlite3
from collections import Counter, deque
from collections.abc import Callable, Sequence
from pathlib import Path

from services.recorder.wear_forecasts import WearForecasts
from shared.contract import RunSummary, ToolData, WearAlert, WearForecast
from shared.errors import InputError
from shared.wear import (
    BrokenLedgerError,
    RefusedSummaryError,
    RunLimits,
    WearLedger,
    load_waiting,
    refusal,
    save_waiting,
    waiting_path,
)

LOG = logging.getLogger(__name__)

PENDING_LIMIT = 100_000  # summaries kept while the ledger cannot be written (days of runs)
#: How often the ledger file is looked at (and waiting summaries tried) with no summary.
CHECK_INTERVAL_NS = 2_000_000_000
REMINDER_INTERVAL_NS = 30_000_000_000
#: At most one log line per this long about refused summaries.
LOG_INTERVAL_NS = 10_000_000_000


class WearWatch:
    """Feed RunSummaries into the ledger; call ``alert`` when a tool is due for service."""

    def __init__(
        self,
        ledger_file: Path,
        threshold: float | None,
        alert: Callable[[WearAlert | WearForecast], None],
        limits: Callable[[RunSummary], RunLimits],
        horizons_days: Sequence[float] = (),
    ) -> None:
        """``alert`` puts a WearAlert or a WearForecast; ``horizons_days``: the horizons a
        tool's forecast is said within (none: no forecast)."""
        self._ledger_file = Path(ledger_file)
        self._ledger: WearLedger | None = None
        self._threshold = threshold
        self._alert = alert
        #: the tools' forecasts (none without a threshold)
        self.forecasts = (
            None if threshold is None else WearForecasts(threshold, horizons_days, alert)
        )
        self._limits = limits
        self._due: set[int] = set()
        self._pending: deque[tuple[RunSummary, int]] = deque(maxlen=PENDING_LIMIT)
        #: what controllers said of their tools, waiting for the ledger: newest per tool
        self._tool_data: dict[tuple[str, int], tuple[ToolData, int]] = {}
        self.tool_data_kept = 0
        self.counted = 0
        self.repeated = 0
        self.refused: Counter[str] = Counter()  # by station
        self.ledger_errors = 0
        self.last_ledger_error: str | None = None
        self.broken = False  # the ledger's file needs a person (boltwatch wear reset)
        self._suspect = False  # read the whole file through (quick_check) before using it
        self._fault_started_ns = 0
        self._remind_at_ns = 0
        self._check_at_ns = 0
        self._refusal_logged_ns: int | None = None
        self._refusals_not_logged = 0
        self._waiting_file = waiting_path(self._ledger_file)
        kept = load_waiting(self._waiting_file)
        self._pending.extend(kept)
        if kept:
            LOG.info(
                "%d run(s) kept waiting for the wear ledger when the recorder last stopped "
                "(%s): counted first",
                len(kept),
                self._waiting_file,
            )

    @property
    def waiting(self) -> int:
        """Summaries waiting in memory for the ledger."""
        return len(self._pending)

    def on_summary(self, summary: RunSummary, now_ns: int) -> bool:
        """Count the run (once); False when it is not counted now (repeated, refused, waiting)."""
        reason = refusal(summary, self._limits(summary))
        if reason is not None:
            self._refuse(RefusedSummaryError(summary, reason), now_ns)
            return False
        if len(self._pending) == PENDING_LIMIT:
            LOG.error("wear ledger: %d summaries waiting, dropping the oldest", PENDING_LIMIT)
        self._pending.append((summary, now_ns))
        return self._write(now_ns, count_errors=True)

    def on_tool_data(self, data: ToolData, now_ns: int) -> None:
        """Keep what a controller said of a tool (the newest per station and tool)."""
        key = (data.station, data.tool_id)
        waiting = self._tool_data.get(key)
        if waiting is None or data.time_ns >= waiting[0].time_ns:
            self._tool_data[key] = (data, now_ns)
        self._write(now_ns, count_errors=True)

    def tick(self, now_ns: int) -> None:
        """Look at the ledger's file now and then; put waiting summaries in when it works."""
        if now_ns < self._check_at_ns:
            return
        self._check_at_ns = now_ns + CHECK_INTERVAL_NS
        nothing_waits = not self._pending and not self._tool_data
        if self._ledger is None and nothing_waits and not self._ledger_file.exists():
            return  # no ledger yet and nothing to count: made by the first summary
        self._write(now_ns, count_errors=False)
        if self.last_ledger_error is not None and now_ns >= self._remind_at_ns:
            self._remind_at_ns = now_ns + REMINDER_INTERVAL_NS
            LOG.error(
                "wear ledger still failing after %.0f s, %d run(s) waiting in memory: %s",
                (now_ns - self._fault_started_ns) / 1e9,
                len(self._pending),
                self.last_ledger_error,
            )

    def _write(self, now_ns: int, count_errors: bool) -> bool:
        """Open and check the ledger, then count every waiting summary, oldest first; whether
        the newest was counted now."""
        counted = False
        try:
            ledger = self._open()
            while self._pending:
                summary, received_ns = self._pending[0]
                try:
                    counted = self._count(ledger, summary, received_ns)
                except RefusedSummaryError as err:  # its limits changed while it waited
                    self._refuse(err, now_ns)
                    counted = False
                self._pending.popleft()
            while self._tool_data:
                key, (data, received_ns) = next(iter(self._tool_data.items()))
                self.tool_data_kept += ledger.add_tool_data(data, received_ns)
                del self._tool_data[key]
            if self._waiting_file.exists():  # every run kept there is in the ledger now
                self._waiting_file.unlink()
        except BrokenLedgerError as err:
            self._failed(err, now_ns, count_errors, broken=True)
            return False
        except (InputError, sqlite3.Error, OSError) as err:
            self._failed(err, now_ns, count_errors, broken=False)
            return False
        if self.last_ledger_error is not None:
            LOG.info(
                "wear ledger %s works again after %.0f s; every waiting run counted",
                self._ledger_file,
                (now_ns - self._fault_started_ns) / 1e9,
            )
            self.last_ledger_error = None
            self.broken = False
        return counted

    def _open(self) -> WearLedger:
        """The open ledger, checked: reopened when its file changed under it."""
        if self._ledger is not None:
            changed = self._ledger.file_changed()
            if changed is None:
                return self._ledger
            LOG.error(
                "wear ledger %s changed while the recorder had it open: %s; opening it again",
                self._ledger_file,
                changed,
            )
            self._suspect = True
            self._close_ledger()
        ledger = WearLedger(self._ledger_file)
        if self._suspect:  # a file that was broken, or changed, is read through first
            try:
                ledger.verify()
            except BaseException:
                ledger.close()
                raise
            self._suspect = False
        self._ledger = ledger
        return ledger

    def _failed(self, err: Exception, now_ns: int, count_errors: bool, broken: bool) -> None:
        self._close_ledger()  # reopened, and checked, at the next try
        starts = self.last_ledger_error is None or broken != self.broken
        if count_errors or starts:
            self.ledger_errors += 1
        self.last_ledger_error = str(err)
        self.broken = broken
        self._suspect = self._suspect or broken
        if not starts:
            return
        self._fault_started_ns = now_ns
        self._remind_at_ns = now_ns + REMINDER_INTERVAL_NS
        if broken:
            LOG.error(
                "wear ledger broken, nothing is written into it: %s; %d run(s) wait in memory "
                "and go into the new ledger once it is started (MCAP recording goes on)",
                err,
                len(self._pending),
            )
        else:
            LOG.error(
                "wear ledger %s cannot be written: %s; %d run(s) wait in memory",
                self._ledger_file,
                err,
                len(self._pending),
            )

    def _close_ledger(self) -> None:
        if self._ledger is not None:
            try:
                self._ledger.close()
            except sqlite3.Error as err:
                LOG.warning("wear ledger %s: closing it failed: %s", self._ledger_file, err)
            self._ledger = None

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

    def _count(self, ledger: WearLedger, summary: RunSummary, now_ns: int) -> bool:
        if not ledger.add_run(summary, now_ns, self._limits(summary)):
            self.repeated += 1
            LOG.debug("run %s/%d already in the ledger", summary.station, summary.run_id)
            return False
        self.counted += 1
        if self._threshold is None:
            return True
        interval = ledger.since_service(summary.tool_id)
        if interval.intensity >= self._threshold:
            if interval.tool_id not in self._due:
                LOG.warning(
                    "tool %d is due for service: intensity %.3g since last service "
                    "(threshold %.3g, %d runs)",
                    interval.tool_id,
                    interval.intensity,
                    self._threshold,
                    interval.runs,
                )
                self._due.add(interval.tool_id)
            self._alert(
                WearAlert(
                    station=summary.station,
                    tool_id=interval.tool_id,
                    time_ns=now_ns,
                    intensity_since_service=interval.intensity,
                    threshold=self._threshold,
                    runs_since_service=interval.runs,
                    last_service_ns=interval.last_service_ns,
                )
            )
        else:
            self._due.discard(interval.tool_id)
        if self.forecasts is not None:
            self.forecasts.after_run(ledger, summary.station, interval, now_ns)
        return True

    def close(self) -> None:
        """Close the ledger; runs still waiting are kept on disk for the next recorder."""
        self._close_ledger()
        if not self._pending:
            return
        try:
            kept = save_waiting(self._waiting_file, self._pending)
        except OSError as err:
            LOG.error(
                "wear ledger: %d run(s) not counted and not kept (%s cannot be written: %s; "
                "last ledger error: %s); their summaries are in the MCAP recordings",
                len(self._pending),
                self._waiting_file,
                err,
                self.last_ledger_error,
            )
            return
        LOG.error(
            "wear ledger: %d run(s) not counted yet (last error: %s); kept in %s, counted "
            "when a recorder starts with a working ledger",
            kept,
            self.last_ledger_error,
            self._waiting_file,
        )
