"""Puts every tightening result the recorder files into the results store
(:mod:`shared.results`), on a thread of its own.

The recorder's worker hands each result over (:meth:`ResultsWatch.on_result`,
with the file it went into; a multi-spindle cycle's common result:
:meth:`ResultsWatch.on_cycle`) and goes on: a slow or unreachable database (a
plant's PostgreSQL across the network) never holds up the recording. A
result is given to the writer (:meth:`ResultsWatch.release`) once the
recorder has flushed its station's files, so the store never holds a result
its recording lost (a recorder killed before the flush): after a kill and
the next start's catch-up the store and the recordings agree. The writer
stores what waits every :data:`WRITE_INTERVAL_S`, in one transaction.

The store failing never stops the recorder, and loses no result:

- while it cannot be opened or written (server down, disk full, a store of a
  newer boltwatch) the results wait in memory, in order, and go in when it
  works again, tried every :data:`RETRY_INTERVAL_S`; logged at ERROR when it
  starts, reminded every :data:`REMINDER_INTERVAL_S` with the count waiting,
  INFO when it works again; ``waiting`` and ``last_error`` say it to
  RecorderStats;
- past :data:`WAITING_LIMIT` the oldest waiting results are let go from memory
  (logged): they are in the recordings, and so is every result still waiting
  when the recorder stops or is killed: at its next start the recorder reads
  again the recordings made since the newest result stored
  (:func:`~shared.results.recordings_reading.fill_from_recordings`, the
  catch-up, on this same thread, before what arrives live).
"""

from __future__ import annotations

import logging
import threading
import time
from collections import OrderedDict, deque
from collections.abc import Callable, Mapping
from datetime import UTC, datetime, timedelta
from pathlib import Path

from shared.config import StationPlace
from shared.contract import CycleResult, RunSummary, TighteningResult
from shared.recordings import loop_lines
from shared.results import ResultsStore, StoredResult, StoreError, StoreTarget, stored_result
from shared.results.recordings_reading import fill_from_recordings, station_recordings
from shared.runtime.log_limit import RateLimitedLog

LOG = logging.getLogger(__name__)

WRITE_INTERVAL_S = 0.2
RETRY_INTERVAL_S = 5.0
REMINDER_INTERVAL_S = 60.0
#: results kept in memory while the store fails (a week of a busy station)
WAITING_LIMIT = 200_000
#: run summaries kept for the results that follow them (their events)
SUMMARIES_KEPT = 1000
#: the catch-up reads recordings modified since the newest stored result less this
CATCH_UP_MARGIN_NS = 120_000_000_000
#: how long a stopping recorder waits for the writer's last transaction
STOP_WAIT_S = 2.0


class ResultsWatch:
    """Store each result filed (with its recording); catch up from recordings at start."""

    def __init__(
        self,
        target: StoreTarget,
        recordings_folder: Path,
        places: Mapping[str, StationPlace],
        host: str,
        open_store: Callable[[StoreTarget], ResultsStore] = ResultsStore,
    ) -> None:
        """``places``: where each station served is (its results and recordings), as its
        station file says (plant, line, name)."""
        self.target = target
        self._folder = recordings_folder
        self._places = dict(places)
        self._host = host
        self._open_store = open_store
        self._store: ResultsStore | None = None
        #: results, and a multi-spindle station's cycles' common results, in the order filed
        self._waiting: deque[StoredResult | CycleResult] = deque()
        #: filed, their files not flushed yet (the recorder's thread only)
        self._unflushed: list[StoredResult | CycleResult] = []
        self._summaries: OrderedDict[tuple[str, int], RunSummary] = OrderedDict()
        self._lock = threading.Lock()
        self._wake = threading.Event()
        self._closing = threading.Event()
        self._started_ns = time.time_ns()
        self._caught_up = False
        self.stored = 0  # results new to the store
        self.repeated = 0  # results it had already
        self.let_go = 0  # waiting results let go from memory (they are in the recordings)
        #: results whose figures cannot be a measurement: kept aside by the store, no result
        self.refused = 0
        self._refusal_log = RateLimitedLog(LOG)
        self.errors = 0
        self.last_error: str | None = None
        self._failing_since_s: float | None = None
        self._remind_at_s = 0.0
        self._thread = threading.Thread(target=self._run, name="results-store", daemon=True)
        self._thread.start()

    @property
    def waiting(self) -> int:
        with self._lock:
            return len(self._waiting)

    def on_summary(self, summary: RunSummary) -> None:
        """Keep a run's summary for its result (events, when the result has none)."""
        key = (summary.station, summary.run_id)
        self._summaries[key] = summary
        self._summaries.move_to_end(key)
        while len(self._summaries) > SUMMARIES_KEPT:
            self._summaries.popitem(last=False)

    def on_result(self, result: TighteningResult, recording: Path | None, now_ns: int) -> None:
        """A filed result (``recording``: the file it went into), stored after
        :meth:`release`."""
        place = self._places.get(result.station, StationPlace())
        self._unflushed.append(
            stored_result(
                result,
                place.line,
                None if recording is None else str(recording.resolve()),
                self._host,
                now_ns,
                self._summaries.get((result.station, result.run_id)),
                plant=place.plant,
                station_name=place.name,
            )
        )

    def on_cycle(self, cycle: CycleResult) -> None:
        """A filed multi-spindle cycle's common result, stored after :meth:`release`."""
        self._unflushed.append(cycle)

    def unflushed_stations(self) -> set[str]:
        """The stations whose filed results wait for their files to be flushed."""
        return {
            filed.station if isinstance(filed, CycleResult) else filed.result.station
            for filed in self._unflushed
        }

    def release(self) -> None:
        """The files of every result filed so far are flushed: to the writer with them."""
        for stored in self._unflushed:
            self._wait(stored)
        self._unflushed.clear()
        self._wake.set()

    def _wait(self, stored: StoredResult | CycleResult) -> None:
        with self._lock:
            if len(self._waiting) >= WAITING_LIMIT:
                self._waiting.popleft()
                self.let_go += 1
                if self.let_go == 1 or self.let_go % 10_000 == 0:
                    LOG.error(
                        "results store %s: %d results waiting; the oldest let go from memory "
                        "(%d so far; they are in the recordings: the next start reads them)",
                        self.target,
                        WAITING_LIMIT,
                        self.let_go,
                    )
            self._waiting.append(stored)

    def close(self) -> None:
        """Store what waits (bounded by :data:`STOP_WAIT_S`), then close the store (the
        recorder has finished its files: every result filed is released)."""
        self.release()
        self._closing.set()
        self._wake.set()
        self._thread.join(STOP_WAIT_S)
        left = self.waiting
        if self._thread.is_alive() or left:
            LOG.warning(
                "results store %s: %d results not stored at stop; the next start reads them "
                "from the recordings",
                self.target,
                left,
            )

    def _run(self) -> None:
        try:
            while True:
                closing = self._closing.is_set()
                self._write_waiting()
                if closing:
                    return
                interval = WRITE_INTERVAL_S if self._failing_since_s is None else RETRY_INTERVAL_S
                self._wake.wait(interval)
                self._wake.clear()
        finally:
            if self._store is not None:
                self._store.close()

    def _write_waiting(self) -> None:
        try:
            store = self._opened()
            if not self._caught_up:
                self._catch_up(store)
            while True:
                with self._lock:
                    batch = list(self._waiting)
                if not batch:
                    break
                refused: list[str] = []
                results = [filed for filed in batch if isinstance(filed, StoredResult)]
                cycles = [filed for filed in batch if isinstance(filed, CycleResult)]
                new = store.add(results, refused)
                if cycles:
                    store.add_cycles(cycles, time.time_ns())
                with self._lock:
                    for _ in batch:
                        self._waiting.popleft()
                self.stored += new
                self.repeated += len(results) - new - len(refused)
                self.refused += len(refused)
                self._name_refused(refused)
        except StoreError as err:
            self._failed(err)
        else:
            self._works_again()

    def _opened(self) -> ResultsStore:
        if self._store is None:
            self._store = self._open_store(self.target)
            if self._store.migrated_from not in (0, self._store.version):
                LOG.info(
                    "results store %s: migrated from version %d to %d",
                    self.target,
                    self._store.migrated_from,
                    self._store.version,
                )
        return self._store

    def _catch_up(self, store: ResultsStore) -> None:
        """Results of recordings made while none was stored (a stop, a kill, a failing
        store): the files modified from the newest stored result (less a margin) up to
        this start."""
        last_ns = store.last_stored_ns(list(self._places))
        since_ns = (last_ns if last_ns is not None else self._started_ns) - CATCH_UP_MARGIN_NS
        # a file is in the day folder of its opening (UTC): the day before may hold one
        # written since
        first_day = datetime.fromtimestamp(since_ns / 1e9, UTC).date() - timedelta(days=1)
        loops: list[Path] = []
        files = [
            path
            for path in station_recordings(self._folder, self._places, first_day, loops)
            if since_ns <= _modified_ns(path) <= self._started_ns
        ]
        for line in loop_lines(loops):
            LOG.warning("results store %s: catch-up: %s; skipped", self.target, line)
        if files:
            counts = fill_from_recordings(store, files, self._places, self._host, time.time_ns)
            LOG.info(
                "results store %s: caught up from %d recordings: %d results, %d new",
                self.target,
                counts.read,
                counts.results,
                counts.new,
            )
            self.stored += counts.new
            self.refused += counts.refused_results
            self._name_refused(counts.refused)
        self._caught_up = True

    def _name_refused(self, lines: list[str]) -> None:
        """Each payload or result refused, in the log: the first at once, then at most one
        line per 10 s (a faulty controller's every result must not flood it)."""
        for line in lines:
            self._refusal_log("results store %s: refused %s", self.target, line)

    def _failed(self, err: StoreError) -> None:
        self.errors += 1
        self.last_error = str(err)
        if self._store is not None:
            self._store.close()
            self._store = None
        now_s = time.monotonic()
        if self._failing_since_s is None:
            self._failing_since_s = now_s
            self._remind_at_s = now_s + REMINDER_INTERVAL_S
            LOG.error("%s; results wait (in memory) and are stored when it works", err)
        elif now_s >= self._remind_at_s:
            self._remind_at_s = now_s + REMINDER_INTERVAL_S
            LOG.error("%s; %d results waiting", err, self.waiting)

    def _works_again(self) -> None:
        if self._failing_since_s is not None:
            LOG.info(
                "results store %s works again after %.0f s",
                self.target,
                time.monotonic() - self._failing_since_s,
            )
            self._failing_since_s = None
            self.last_error = None


def _modified_ns(path: Path) -> int:
    try:
        return path.stat().st_mtime_ns
    except FileNotFoundError:
        return -1
