"""The results store: every tightening's result, findable by part, station, plant, line,
program, tool and time (:mod:`.results_schema` its tables, :mod:`.results_database` SQLite
or PostgreSQL).

The recorder adds each result as it files it (``services/recorder/results_watch.py``),
``boltwatch results rebuild`` those of existing recordings; both may write at once.
:meth:`ResultsStore.add` is idempotent by (station, run_id): a result stored
again is left as it is (the first one stored stays) and not counted as new. A
tightening whose figures cannot be a measurement is kept aside and named, never
a result to a reader (:mod:`.refused_results`; :meth:`ResultsStore.refused`
names those a question asks for). :meth:`ResultsStore.verdicts` says which runs
are stored, kept aside or not (the retention policy deletes no recording whose
results are not). Readers (``boltwatch results``,
``report``, ``recordings prune``) open it without making one:
:class:`~.results_database.StoreError` says where none is and how one comes.
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Iterator, Sequence
from typing import Any

from shared.contract import CycleResult, ResultStep
from shared.quality import implausible, refusal_line
from shared.results.refused_results import LINE_COLUMNS, refused_line
from shared.results.results_database import ResultsDatabase, StoreError, StoreTarget
from shared.results.results_query import ResultsQuery
from shared.results.results_schema import (
    CYCLE_COLUMNS,
    SCHEMA_VERSION,
    STEP_COLUMNS,
    TIGHTENING_COLUMNS,
    migrate,
    version_of,
)
from shared.results.sqlite_statistics import FEWEST_ROWS, keep_statistics, statistics_missing
from shared.results.stored_result import (
    RunCycle,
    StoredResult,
    cycle_of,
    cycle_rows,
    from_row,
    step_of,
    step_rows,
    stored_cycle,
    to_row,
)

LOG = logging.getLogger(__name__)

#: run ids of one station per statement when rows are read by key (steps, verdicts)
_RUNS_PER_QUERY = 500

#: the table of results, and the one of tightenings kept aside (:mod:`.refused_results`)
RESULTS_TABLE, REFUSED_TABLE = "tightenings", "refused_tightenings"
_INSERT = {
    table: f"INSERT INTO {table} ({', '.join(TIGHTENING_COLUMNS)}) "
    f"VALUES ({', '.join('?' * len(TIGHTENING_COLUMNS))}) "
    "ON CONFLICT (station, run_id) DO NOTHING"
    for table in (RESULTS_TABLE, REFUSED_TABLE)
}
_INSERT_STEP = (
    f"INSERT INTO tightening_steps ({', '.join(STEP_COLUMNS)}) "
    f"VALUES ({', '.join('?' * len(STEP_COLUMNS))}) "
    "ON CONFLICT (station, run_id, step_index) DO NOTHING"
)
_INSERT_CYCLE = (
    f"INSERT INTO cycle_results ({', '.join(CYCLE_COLUMNS)}) "
    f"VALUES ({', '.join('?' * len(CYCLE_COLUMNS))}) "
    "ON CONFLICT (station, run_id) DO NOTHING"
)
_SELECT = f"SELECT {', '.join(TIGHTENING_COLUMNS)} FROM tightenings"


class ResultsStore:
    """An open results store (a context manager)."""

    _statistics_rows = 0  # a writer's: the rows its SQLite statistics stand for

    def __init__(self, target: StoreTarget, *, create: bool = True, application: str = "") -> None:
        """``create``: make the store when there is none (a writer); else StoreError.
        An older store is migrated either way; a reader (``create=False``) of a store at
        this version changes nothing but SQLite's planner statistics when it has none, and
        waits for no writer (:meth:`_describe_for_readers`: the recorder is never kept waiting)."""
        self.target = target
        nowhere = StoreError(
            f"no results store at {target}: the line's recorder makes it, "
            "'boltwatch results rebuild' fills it from existing recordings"
        )
        if not create and target.sqlite_path is not None and not target.sqlite_path.exists():
            raise nowhere  # opening would make the file
        self.database = ResultsDatabase(target, application or "boltwatch")
        try:
            if create:
                self.migrated_from = migrate(self.database)
                self._keep_statistics()
            else:
                found = version_of(self.database)
                if found == 0:
                    raise nowhere
                self.migrated_from = found if found == SCHEMA_VERSION else migrate(self.database)
                self._describe_for_readers()
        except BaseException:
            self.database.close()
            raise
        self.version = SCHEMA_VERSION
        self._added_since_statistics = 0

    def close(self) -> None:
        self.database.close()

    def __enter__(self) -> ResultsStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def add(self, results: Sequence[StoredResult], refused: list[str] | None = None) -> int:
        """Store ``results`` in one transaction; how many were new results (not stored
        before). One whose figures cannot be a measurement is kept aside instead (not a
        result: not counted), a line naming it in ``refused``, stored before or not."""
        inserted: dict[tuple[str, int], tuple[StoredResult, str | None]] = {}
        with self.database.transaction():
            for stored in results:
                result = stored.result
                fault = implausible(result)
                key = (result.station, result.run_id)
                table = RESULTS_TABLE if fault is None else REFUSED_TABLE
                if key not in inserted and self.database.execute(_INSERT[table], to_row(stored)):
                    inserted[key] = (stored, fault)
                if fault is not None and refused is not None:
                    refused.append(
                        refusal_line(result.station, result.run_id, result.tool_id, fault)
                    )
            # the first stored stays, whichever table it went into: one just inserted whose
            # run the other table holds (two payloads of one run) is taken back (after the
            # inserts: a SQLite transaction that reads first cannot write when another
            # writer has written meanwhile)
            for key in self._held_by_the_other_table(inserted):
                fault = inserted.pop(key)[1]
                self.database.execute(
                    f"DELETE FROM {RESULTS_TABLE if fault is None else REFUSED_TABLE} "
                    "WHERE station = ? AND run_id = ?",
                    key,
                )
            for stored, _ in inserted.values():
                self.database.execute_many(_INSERT_STEP, step_rows(stored))
        new = sum(1 for _, fault in inserted.values() if fault is None)
        self._added_since_statistics += new
        if self._added_since_statistics >= max(self._statistics_rows, FEWEST_ROWS):
            self._keep_statistics()
        return new

    def add_cycles(self, cycles: Sequence[CycleResult], stored_ns: int) -> int:
        """Store multi-spindle cycles' common results in one transaction (idempotent, as
        :meth:`add`: a spindle's run keeps the first cycle stored for it); how many spindles'
        runs were new."""
        new = 0
        with self.database.transaction():
            for cycle in cycles:
                for row in cycle_rows(cycle, stored_ns):
                    new += bool(self.database.execute(_INSERT_CYCLE, row))
        return new

    def _held_by_the_other_table(
        self, inserted: dict[tuple[str, int], tuple[StoredResult, str | None]]
    ) -> set[tuple[str, int]]:
        """The keys of ``inserted`` (each with its fault: None went into tightenings) that
        the other table holds."""
        held: set[tuple[str, int]] = set()
        for other, keys in (
            (REFUSED_TABLE, [key for key, (_, fault) in inserted.items() if fault is None]),
            (RESULTS_TABLE, [key for key, (_, fault) in inserted.items() if fault is not None]),
        ):
            for station, run_ids in _runs_by_station(keys):
                rows = self.database.rows(
                    f"SELECT run_id FROM {other} "
                    f"WHERE station = ? AND run_id IN ({', '.join('?' * len(run_ids))})",
                    [station, *run_ids],
                )
                held.update((station, int(row[0])) for row in rows)
        return held

    def _keep_statistics(self) -> None:
        """SQLite's planner statistics brought up to date (:mod:`.sqlite_statistics`), as best
        effort: the results are stored whether they can be or not (a busy store, an index
        they cannot describe); a failure is logged and tried again after as many adds."""
        self._added_since_statistics = 0
        try:
            self._statistics_rows = keep_statistics(self.database)
        except StoreError as err:
            LOG.warning("results store %s: planner statistics not written: %s", self.target, err)

    def _describe_for_readers(self) -> None:
        """A reader's open: a SQLite store no writer has described (:mod:`.sqlite_statistics`)
        gets its statistics now, as best effort: when the file is writable and no writer holds
        the store (waited for by no one); otherwise it is read as it is."""
        try:
            if statistics_missing(self.database):
                with self.database.not_waiting():
                    keep_statistics(self.database)
        except StoreError as err:
            LOG.info("results store %s: planner statistics not written: %s", self.target, err)

    def find(self, query: ResultsQuery) -> list[StoredResult]:
        """The tightenings ``query`` asks for, with their steps, in its order."""
        where, parameters = query.where()
        sync_column = TIGHTENING_COLUMNS.index("sync_id")
        with self.database.transaction():
            rows = self.database.rows(_SELECT + where + query.order(), parameters)
            steps = self._steps_of([(row[0], row[1]) for row in rows])
            cycles = self._cycles_of(
                [(row[0], row[1]) for row in rows if row[sync_column] is not None]
            )
        return [
            dataclasses.replace(
                from_row(row, steps.get((row[0], int(row[1])), ())),
                cycle=cycles.get((row[0], int(row[1]))),
            )
            for row in rows
        ]

    def keys(self, query: ResultsQuery) -> list[tuple[str, int]]:
        """The (station, run id) of the tightenings ``query`` asks for, in its order: what
        :meth:`find` gives without reading the rows and their steps (an OPC UA client's
        list of ResultIds)."""
        where, parameters = query.where()
        with self.database.transaction():
            rows = self.database.rows(
                "SELECT station, run_id FROM tightenings" + where + query.order(), parameters
            )
        return [(str(row[0]), int(row[1])) for row in rows]

    def count(self, query: ResultsQuery) -> int:
        """How many tightenings ``query`` asks for (its limit aside)."""
        where, parameters = query.where()
        with self.database.transaction():
            (row,) = self.database.rows("SELECT COUNT(*) FROM tightenings" + where, parameters)
        return int(row[0])

    def recording_read(self, host: str, recording: str) -> tuple[int, int] | None:
        """(size, modification time) of ``recording`` when it was last read; None: never."""
        with self.database.transaction():
            rows = self.database.rows(
                "SELECT size_bytes, modified_ns FROM recordings_read "
                "WHERE recording_host = ? AND recording = ?",
                (host, recording),
            )
        return (int(rows[0][0]), int(rows[0][1])) if rows else None

    def mark_read(
        self,
        host: str,
        recording: str,
        size_bytes: int,
        modified_ns: int,
        results: int,
        now_ns: int,
    ) -> None:
        """``recording`` has been read whole at (size, modification time)."""
        with self.database.transaction():
            self.database.execute(
                "INSERT INTO recordings_read (recording_host, recording, size_bytes, "
                "modified_ns, results, read_ns) VALUES (?, ?, ?, ?, ?, ?) "
                "ON CONFLICT (recording_host, recording) DO UPDATE SET "
                "size_bytes = excluded.size_bytes, modified_ns = excluded.modified_ns, "
                "results = excluded.results, read_ns = excluded.read_ns",
                (host, recording, size_bytes, modified_ns, results, now_ns),
            )

    def refused(self, query: ResultsQuery) -> list[str]:
        """A line naming each tightening ``query`` asks for (its limit aside) that was kept
        aside (:mod:`.refused_results`), in the order they ended: what ``report`` says of the
        same results read from their files."""
        where, parameters = dataclasses.replace(query, limit=None, oldest_first=True).where()
        order = " ORDER BY ended_ns, station, run_id"
        with self.database.transaction():
            rows = self.database.rows(
                f"SELECT {LINE_COLUMNS} FROM {REFUSED_TABLE}{where}{order}", parameters
            )
        return [refused_line(row) for row in rows]

    def last_stored_ns(self, stations: Sequence[str]) -> int | None:
        """When the newest tightening of ``stations`` was stored (kept aside or not); None:
        none stored."""
        where, parameters = ResultsQuery(stations=stations).where()
        newest = []
        with self.database.transaction():
            for table in (RESULTS_TABLE, REFUSED_TABLE):
                (row,) = self.database.rows(
                    f"SELECT MAX(stored_ns) FROM {table}" + where, parameters
                )
                newest += [int(row[0])] if row[0] is not None else []
        return max(newest, default=None)

    def verdicts(self, keys: Sequence[tuple[str, int]]) -> dict[tuple[str, int], str]:
        """The result (``OK``/``NOK``) of each of ``keys`` (station, run_id) that is stored,
        kept aside or not; a key not stored is not in the answer."""
        found: dict[tuple[str, int], str] = {}
        with self.database.transaction():
            for station, run_ids in _runs_by_station(keys):
                for table in (RESULTS_TABLE, REFUSED_TABLE):
                    rows = self.database.rows(
                        f"SELECT run_id, result FROM {table} "
                        f"WHERE station = ? AND run_id IN ({', '.join('?' * len(run_ids))})",
                        [station, *run_ids],
                    )
                    found.update({(station, int(row[0])): row[1] for row in rows})
        return found

    def cycle(self, station: str, sync_id: int) -> CycleResult | None:
        """The common result of ``station``'s multi-spindle cycle ``sync_id`` (the newest
        cycle of that sync id), each spindle with its run's verdict; None: none stored."""
        rows = self.database.rows(
            "SELECT run_id, spindle, spindles, result, nok_reasons, ended_ns, part_id, "
            "program_id, source FROM cycle_results WHERE station = ? AND sync_id = ? "
            "ORDER BY ended_ns DESC, spindle",
            [station, sync_id],
        )
        if not rows:
            return None
        newest = [row for row in rows if row[5] == rows[0][5]]
        verdicts = self.verdicts([(station, int(row[0])) for row in newest])
        return stored_cycle(
            station, sync_id, newest, {run: verdict for (_, run), verdict in verdicts.items()}
        )

    def _cycles_of(self, keys: list[tuple[Any, Any]]) -> dict[tuple[str, int], RunCycle]:
        """The multi-spindle cycle of each of ``keys`` ((station, run_id) pairs) stored."""
        sql = (
            "SELECT run_id, sync_id, spindles, result, nok_reasons, ended_ns FROM cycle_results "
            "WHERE station = ? AND run_id IN ({runs})"
        )
        return {
            (station, int(row[0])): cycle_of(row[1:])
            for station, row in _keyed_rows(self.database, sql, keys)
        }

    def _steps_of(self, keys: list[tuple[Any, Any]]) -> dict[tuple[str, int], list[ResultStep]]:
        """The steps of the tightenings ``keys`` ((station, run_id) pairs)."""
        steps: dict[tuple[str, int], list[ResultStep]] = {}
        for station, run_ids in _runs_by_station(keys):
            rows = self.database.rows(
                "SELECT run_id, name, function, nominal, actual, status FROM tightening_steps "
                f"WHERE station = ? AND run_id IN ({', '.join('?' * len(run_ids))}) "
                "ORDER BY run_id, step_index",
                [station, *run_ids],
            )
            for row in rows:
                steps.setdefault((station, int(row[0])), []).append(step_of(row[1:]))
        return steps


def _keyed_rows(
    database: Any, sql: str, keys: Sequence[tuple[Any, Any]]
) -> Iterator[tuple[str, Any]]:
    """(station, row) of ``sql`` (``... WHERE station = ? AND run_id IN ({runs})``) for
    ``keys``, asked by station, a bounded number of runs per statement."""
    for station, run_ids in _runs_by_station(keys):
        for row in database.rows(
            sql.format(runs=", ".join("?" * len(run_ids))), [station, *run_ids]
        ):
            yield station, row


def _runs_by_station(keys: Sequence[tuple[Any, Any]]) -> Iterator[tuple[str, list[int]]]:
    """``keys`` ((station, run_id) pairs, each once) as (station, up to :data:`_RUNS_PER_QUERY`
    of its run ids): what a statement asks, each found by the primary key. (A list of pairs,
    ``(station, run_id) IN ((?, ?), ...)``, is not: SQLite reads the whole table for it.)"""
    runs: dict[str, list[int]] = {}
    for station, run_id in dict.fromkeys(keys):
        runs.setdefault(station, []).append(int(run_id))
    for station, run_ids in runs.items():
        for start in range(0, len(run_ids), _RUNS_PER_QUERY):
            yield station, run_ids[start : start + _RUNS_PER_QUERY]
