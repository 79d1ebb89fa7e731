"""Applies the stations' ``[retention]`` to their recordings, on a thread of its own
(:mod:`shared.retention`).

The recorder's worker tells it at each tick which files it has open
(:meth:`RetentionWatch.open_files`: a set of a few paths, nothing else on the
recording's path); the thread runs a pass as soon as it first knows them,
then every :data:`PASS_INTERVAL_S`: it lists the stations' run files, asks
the results store what each file a rule would delete holds (its own
connection, opened for the pass), and deletes what the plan says, each
``.mcap`` with its ``.rrd``. A file whose results are not all stored is kept
and counted; nothing is deleted while the store cannot be asked (tried again
every :data:`RETRY_INTERVAL_S`).

Logged: one INFO line per pass that deleted anything (how many, bytes,
written from when to when, per reason), each file at DEBUG; a WARNING when
files past their time are kept (results not stored, unreadable) or the disk
stays above its limit, again when that changes or every
:data:`REMINDER_INTERVAL_S`; the store failing once, and when it works
again; a pass failing otherwise (a folder it may not read) with its
traceback, at most hourly. ``deleted`` and ``kept_not_stored`` (per station)
go into each station's RecorderStats, ``last_error`` into their
``last_error``.
"""

from __future__ import annotations

import logging
import shutil
import threading
import time
from collections import Counter
from collections.abc import Callable, Collection
from pathlib import Path

from shared.results import ResultsStore, StoreError, StoreTarget
from shared.retention import (
    NOT_STORED,
    FileResultsCache,
    Measure,
    PruneOutcome,
    RetentionPlan,
    RetentionScope,
    bytes_text,
    delete_planned,
    deleted_tallies,
    plan_pass,
    reason_text,
)

LOG = logging.getLogger(__name__)

#: how often a pass runs (seconds): the curves of ~100 KB a run need no more
PASS_INTERVAL_S = 600.0
#: how soon a pass is tried again after the store could not be asked (seconds)
RETRY_INTERVAL_S = 60.0
#: an unchanged warning (files kept, the disk above its limit) is said again this often
REMINDER_INTERVAL_S = 3600.0
#: how long a stopping recorder waits for a pass under way (it stops between two files)
STOP_WAIT_S = 10.0


class RetentionWatch:
    """Delete the recordings ``scope``'s policy lets go, every few minutes."""

    def __init__(
        self,
        scope: RetentionScope,
        interval_s: float = PASS_INTERVAL_S,
        measure: Measure = shutil.disk_usage,
        open_store: Callable[[StoreTarget], ResultsStore] = ResultsStore,
    ) -> None:
        self.scope = scope
        self._interval_s = interval_s
        self._measure = measure
        self._open_store = open_store
        self._cache = FileResultsCache()
        self._lock = threading.Lock()
        self._open_paths: frozenset[Path] | None = None  # None: not told yet
        self._wake = threading.Event()
        self._closing = threading.Event()
        self.passes = 0
        self._named_skipped: set[str] = set()  # symlink loops met, logged once each
        self.deleted: Counter[str] = Counter()  # per station, since the recorder started
        self.kept_not_stored: dict[str, int] = {}  # per station, at the last pass
        self.failed_deletions = 0
        self.last_error: str | None = None
        self._store_failing = False
        self._error_reminder_s = 0.0
        self._warned: tuple[object, float] = ((), 0.0)  # what was warned of, and when
        LOG.info(
            "retention of %s (%s): %s; a pass every %.0f s",
            scope.folder,
            ", ".join(scope.stations),
            scope.policy.describe(),
            interval_s,
        )
        self._thread = threading.Thread(target=self._run, name="retention", daemon=True)
        self._thread.start()

    def open_files(self, paths: Collection[Path]) -> None:
        """The files the recorder has open now (the worker, at each tick)."""
        opened = frozenset(paths)
        with self._lock:
            first = self._open_paths is None
            self._open_paths = opened
        if first:
            self._wake.set()

    def close(self) -> None:
        self._closing.set()
        self._wake.set()
        self._thread.join(STOP_WAIT_S)

    def _run(self) -> None:
        while not self._closing.is_set():
            with self._lock:
                opened = self._open_paths
            if opened is None:  # the worker has not said which files it has open yet
                self._wake.wait()
                self._wake.clear()
                continue
            done = self._pass(opened)
            self._wake.wait(self._interval_s if done else min(self._interval_s, RETRY_INTERVAL_S))
            self._wake.clear()

    def _pass(self, opened: frozenset[Path]) -> bool:
        """One pass; False when it could not be made (tried again sooner)."""
        try:
            with self._open_store(self.scope.target) as store:
                plan = plan_pass(
                    self.scope,
                    store,
                    self._cache,
                    time.time_ns(),
                    opened,
                    self._measure,
                    stop=self._closing,
                )
        except StoreError as err:
            self.last_error = f"retention: {err}"
            if not self._store_failing:
                self._store_failing = True
                LOG.warning(
                    "retention: %s; nothing is deleted until the store can be asked "
                    "(tried again every %.0f s)",
                    err,
                    RETRY_INTERVAL_S,
                )
            return False
        except Exception as err:  # a pass never ends the thread: the next one tries again
            self.last_error = f"retention: {err}"
            now_s = time.monotonic()
            if now_s >= self._error_reminder_s:  # the traceback once, then hourly
                self._error_reminder_s = now_s + REMINDER_INTERVAL_S
                LOG.exception("retention: the pass over %s failed", self.scope.folder)
            return False
        if self._store_failing:
            self._store_failing = False
            LOG.info("retention: the results store %s answers again", self.scope.target)
        self.last_error = None
        self._error_reminder_s = 0.0
        if self._closing.is_set():
            return True  # stopping: what it planned is done at the next start
        outcome = delete_planned(plan)
        self.passes += 1
        self._count(plan, outcome)
        self._log(plan, outcome)
        return True

    def _count(self, plan: RetentionPlan, outcome: PruneOutcome) -> None:
        for decision in outcome.deleted:
            self.deleted[decision.file.station] += 1
        kept: Counter[str] = Counter(
            decision.file.station for decision in plan.kept if decision.reason == NOT_STORED
        )
        self.kept_not_stored = {station: kept[station] for station in self.scope.stations}
        self.failed_deletions += len(outcome.failed)

    def _log(self, plan: RetentionPlan, outcome: PruneOutcome) -> None:
        policy = self.scope.policy
        for decision in outcome.deleted:
            LOG.debug("retention: deleted %s (%s)", decision.file.path, decision.reason)
        tallies = deleted_tallies(outcome.deleted)
        if tallies:
            reasons = "; ".join(
                f"{tally.files} {reason_text(reason, policy, plan.usage)}"
                for reason, tally in tallies.items()
                if reason
            )
            LOG.info("retention: deleted %s: %s", tallies[""].text(), reasons)
        if outcome.failed:
            decision, why = outcome.failed[0]
            LOG.warning(
                "retention: %d recordings not deleted (the first: %s: %s)",
                len(outcome.failed),
                decision.file.path,
                why,
            )
        self._warn_kept(plan)
        for line in plan.skipped:  # each once, not every pass
            if line not in self._named_skipped:
                self._named_skipped.add(line)
                LOG.warning("retention: %s; skipped, never touched", line)

    def _warn_kept(self, plan: RetentionPlan) -> None:
        """Files kept past their time, the disk above its limit: said when it changes, and
        again every REMINDER_INTERVAL_S."""
        kept = Counter(decision.reason for decision in plan.kept)
        state = (tuple(sorted(kept.items())), plan.disk_short_bytes > 0)
        now_s = time.monotonic()
        said, said_s = self._warned
        if state == said and now_s - said_s < REMINDER_INTERVAL_S:
            return
        self._warned = (state, now_s)
        policy = self.scope.policy
        if plan.kept:
            first = plan.kept[0]
            LOG.warning(
                "retention: %d recordings past their time kept: %s (the oldest: %s)",
                len(plan.kept),
                "; ".join(
                    f"{n} file{'' if n == 1 else 's'}: {reason_text(reason, policy)}"
                    for reason, n in sorted(kept.items())
                ),
                first.file.path,
            )
        if plan.disk_short_bytes and plan.usage is not None:
            LOG.warning(
                "retention: the disk of %s is %.1f %% used, above max_disk_used_pct %g %%, "
                "and %s more would have to go: nothing else may (kept past their time, "
                "open, the newest of a station, written in the last hour, or not recordings)",
                self.scope.folder,
                plan.usage.used_pct,
                policy.max_disk_used_pct,
                bytes_text(plan.disk_short_bytes),
            )
