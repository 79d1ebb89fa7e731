"""The wear ledger: how much stick-slip vibration each tool has taken (SQLite, WAL).

Every RunSummary adds its run's process intensity I_process (eq. 68) to its
tool; a tool's accumulated intensity is the paper's eq. 69,
``I_total = Σ_runs I_process``. A loosening (``RunSummary.operation``: an
imported controller run that turned the tool back) vibrates the tool too: its
intensity counts in the tool's totals, since service as well, but it is not
one of the tool's tightenings (``runs``, ``runs_since_service``: what the
OPC UA server gives as the tool's tightenings); ``loosenings`` counts it.
Runs are keyed by (station, run_id), so a
summary delivered twice, or seen again after a recorder restart, is counted
once. Tools are physical assets (a tool id is unique in the plant): a tool's
totals count its runs at every station, and each run keeps the station it
ran at, so a station's view (``tools(station=...)``, the
``boltwatch/<st>/wear`` queryable, ``boltwatch wear --station``) is the tools
that ran there, with their whole totals. A service (``boltwatch wear service
TOOL``) starts a new interval: "intensity since service" counts runs that
ended after it, while the run history and the all-time total stay.

The file is ``<recordings>/wear.sqlite`` in WAL mode: the recorder writes,
``boltwatch wear`` and the ``wear`` queryable read at the same time: a
reader holding a read transaction never blocks the writer, nor the writer a
reader. Each run is one transaction: a writer killed mid-run loses that run
only, and the file stays consistent (``tests/system/test_wear_ledger_kill.py``).

A run enters only within what its tool can have taken
(:mod:`.wear_bound`: :class:`~.wear_bound.RefusedSummaryError` otherwise).
A file at the path that is no ledger (empty, not SQLite, another schema,
corrupt) is never written into: :class:`~.wear_ledger_file.BrokenLedgerError`
(:mod:`.wear_ledger_file`: how a new ledger is made, and a broken one
recognised and moved aside).
"""

from __future__ import annotations

import contextlib
import logging
import sqlite3
import time
from collections.abc import Iterator, Mapping
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from shared.contract import RunSummary, ToolData
from shared.errors import InputError
from shared.wear import wear_tool_data
from shared.wear.wear_bound import RefusedSummaryError, RunLimits, refusal
from shared.wear.wear_calendar import DAY_NS
from shared.wear.wear_forecast import SHIPPED, ForecastSettings
from shared.wear.wear_history import first_and_last, grouped_runs, ledger_calendar, unusual_runs
from shared.wear.wear_ledger_file import (
    COLUMNS,
    LEDGER_VERSION,
    BrokenLedgerError,
    create_ledger,
    file_problem,
    has_column,
    identity,
    is_broken_error,
    migrate,
    schema_problem,
)
from shared.wear.wear_outlook import ToolOutlook, run_limits, tool_outlook
from shared.wear.wear_since_service import TIGHTENING, ServiceInterval, SinceServiceTally
from shared.wear.wear_tool_data import ControllerTool

LOG = logging.getLogger(__name__)

LEDGER_FILE = "wear.sqlite"
WORST_RUNS = 3

_SCHEMA = (
    """
CREATE TABLE IF NOT EXISTS runs (
    station TEXT NOT NULL,
    run_id INTEGER NOT NULL,
    tool_id INTEGER NOT NULL,
    program_id INTEGER NOT NULL,
    tool_state TEXT NOT NULL,
    stop_reason TEXT,
    events INTEGER NOT NULL,
    process_intensity REAL NOT NULL,
    started_ns INTEGER NOT NULL,
    ended_ns INTEGER NOT NULL,
    recorded_ns INTEGER NOT NULL,
    operation TEXT NOT NULL DEFAULT 'tightening',
    PRIMARY KEY (station, run_id)
);
CREATE INDEX IF NOT EXISTS runs_by_tool ON runs (tool_id, ended_ns);
CREATE INDEX IF NOT EXISTS runs_by_station ON runs (station, tool_id);
CREATE TABLE IF NOT EXISTS services (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    tool_id INTEGER NOT NULL,
    serviced_ns INTEGER NOT NULL,
    note TEXT NOT NULL
);
"""
    + wear_tool_data.SCHEMA
)


@dataclass(frozen=True, slots=True)
class RunWear:
    station: str
    run_id: int
    process_intensity: float
    ended_ns: int


@dataclass(frozen=True, slots=True)
class ToolWear:
    """One tool's line of the ledger."""

    tool_id: int
    runs: int  # its tightenings
    total_intensity: float  # I_total, eq. 69: of its tightenings and loosenings
    intensity_per_run: float  # of every run, tightening or loosening
    last_service_ns: int | None
    last_service_note: str | None
    runs_since_service: int
    intensity_since_service: float
    worst_runs: list[RunWear] = field(default_factory=list)
    stations: list[str] = field(default_factory=list)  # where its runs were, by name
    # what its controller said of it last (serial, counters, calibration, service); None:
    # no controller bridge spoke of it
    controller: ControllerTool | None = None
    loosenings: int = 0  # its loosenings (their intensity is in the totals)
    # its pace of wear, what wears it (:mod:`.wear_outlook`): what a forecast against any
    # threshold needs (:func:`~.wear_forecast.forecast`); None: not asked for, or no run
    outlook: ToolOutlook | None = None

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def ledger_path(recordings: Path) -> Path:
    return Path(recordings) / LEDGER_FILE


class WearLedger:
    """The ledger file through one connection, for one thread at a time."""

    def __init__(self, path: Path, read_only: bool = False, busy_timeout_s: float = 10.0) -> None:
        """Open the ledger at ``path`` (the writer makes it when there is none).

        BrokenLedgerError when the file there is no usable ledger; InputError when
        SQLite cannot open it otherwise (OSError: the folder cannot be made).
        """
        self.path = Path(path)
        if read_only and not self.path.is_file():
            raise InputError(f"{self.path}: no wear ledger here (nothing recorded yet?)")
        if not read_only:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            if not self.path.exists():
                create_ledger(self.path, _SCHEMA)
        problem = file_problem(self.path)
        if problem is not None:
            raise BrokenLedgerError(self.path, problem)
        db: sqlite3.Connection | None = None
        try:
            if read_only:
                uri = f"{self.path.resolve().as_uri()}?mode=ro"
                db = sqlite3.connect(uri, uri=True, timeout=busy_timeout_s)
            else:
                # Opened by the thread that builds the service, then used by its worker only.
                db = sqlite3.connect(self.path, timeout=busy_timeout_s, check_same_thread=False)
            #: the file this connection reads and writes: another one at the path is not it
            self.identity = identity(self.path)
            problem = schema_problem(db)
            if problem is not None:
                raise BrokenLedgerError(self.path, problem)
            if not read_only:
                db.execute("PRAGMA journal_mode=WAL")
                self._migrate(db)
            #: SQL true for a tightening (a ledger before version 3 holds tightenings only)
            self._tightening = TIGHTENING if has_column(db, "runs", "operation") else "1"
        except (sqlite3.Error, BrokenLedgerError) as err:
            if db is not None:
                db.close()
            if isinstance(err, BrokenLedgerError):
                raise
            if is_broken_error(err):
                raise BrokenLedgerError(self.path, str(err)) from err
            raise InputError(f"{self.path}: not a usable wear ledger: {err}") from err
        self._db = db
        self._since_service = SinceServiceTally(self._tightening)

    def _migrate(self, db: sqlite3.Connection) -> None:
        was = migrate(db, _SCHEMA)
        if was is not None:
            LOG.info(
                "wear ledger %s: version %d made version %d (tool data added; its runs and "
                "services kept)",
                self.path,
                was,
                LEDGER_VERSION,
            )

    @contextlib.contextmanager
    def _reading_the_file(self) -> Iterator[None]:
        """SQLite finding the file damaged is a BrokenLedgerError; other errors stay."""
        try:
            yield
        except sqlite3.Error as err:
            if is_broken_error(err):
                raise BrokenLedgerError(self.path, str(err)) from err
            raise

    def file_changed(self) -> str | None:
        """What happened to the file this ledger opened, or None: removed, replaced by
        another file, emptied or overwritten (OSError when the path cannot be read)."""
        try:
            now = identity(self.path)
        except FileNotFoundError:
            return "it was removed"
        if now != self.identity:
            return "another file took its place"
        return file_problem(self.path)

    def verify(self) -> None:
        """Read the whole file through (``PRAGMA quick_check``); BrokenLedgerError if damaged."""
        with self._reading_the_file():
            rows = [str(row[0]) for row in self._db.execute("PRAGMA quick_check")]
        if rows != ["ok"]:
            raise BrokenLedgerError(self.path, f"corrupt: {'; '.join(rows[:3])}")

    def add_run(self, summary: RunSummary, recorded_ns: int, limits: RunLimits) -> bool:
        """Count a run once; False when (station, run_id) was already in the ledger.

        RefusedSummaryError when the summary is beyond ``limits`` (:mod:`.wear_bound`).
        """
        reason = refusal(summary, limits)
        if reason is not None:
            raise RefusedSummaryError(summary, reason)
        with self._reading_the_file(), self._db:
            cursor = self._db.execute(
                f"INSERT OR IGNORE INTO runs ({', '.join(COLUMNS['runs'])}) "
                "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                (
                    summary.station,
                    summary.run_id,
                    summary.tool_id,
                    summary.program_id,
                    summary.tool_state,
                    summary.stop_reason,
                    summary.events,
                    summary.process_intensity,
                    summary.started_ns,
                    summary.ended_ns,
                    recorded_ns,
                    summary.operation,
                ),
            )
        return cursor.rowcount == 1

    def since_service(self, tool_id: int) -> ServiceInterval:
        """The tool's runs and intensity since its last service, without reading its whole
        interval each time (:mod:`.wear_since_service`)."""
        with self._reading_the_file(), self._db:
            self._db.execute("BEGIN")
            return self._since_service.interval(self._db, tool_id)

    def add_tool_data(self, data: ToolData, recorded_ns: int) -> bool:
        """Keep what a controller said of a tool; False when a newer one is kept already."""
        with self._reading_the_file():
            return wear_tool_data.store(self._db, data, recorded_ns)

    def record_service(self, tool_id: int, note: str, serviced_ns: int) -> None:
        """A service of ``tool_id`` now: starts a new interval, keeps the history."""
        with self._reading_the_file(), self._db:
            self._db.execute(
                "INSERT INTO services (tool_id, serviced_ns, note) VALUES (?, ?, ?)",
                (tool_id, serviced_ns, note),
            )

    def tool_ids(self, station: str | None = None) -> list[int]:
        """Every tool in the ledger, or those that ran at ``station``; by id."""
        with self._reading_the_file():
            return self._tool_ids(station)

    def _tool_ids(self, station: str | None) -> list[int]:
        if station is not None:
            rows = self._db.execute(
                "SELECT DISTINCT tool_id FROM runs WHERE station = ?", (station,)
            )
        else:
            rows = self._db.execute("SELECT tool_id FROM runs UNION SELECT tool_id FROM services")
        found = {int(tool_id) for (tool_id,) in rows}
        return sorted(found.union(wear_tool_data.tool_ids(self._db, station)))

    def tools(
        self,
        station: str | None = None,
        *,
        outlook: bool = True,
        joints: Mapping[tuple[str, int], str] | None = None,
    ) -> list[ToolWear]:
        """Every tool's line (or of the tools that ran at ``station``, whole totals), by id;
        ``outlook``: with its pace and causes of wear (``joints``: each station's program's
        joint, where known)."""
        return [
            self.tool(tool_id, outlook=outlook, joints=joints) for tool_id in self.tool_ids(station)
        ]

    def tool(
        self,
        tool_id: int,
        *,
        outlook: bool = True,
        joints: Mapping[tuple[str, int], str] | None = None,
    ) -> ToolWear:
        """One tool's line (zeros for a tool the ledger has never seen); ``outlook`` as for
        :meth:`tools`."""
        # One read transaction, so the figures agree with each other under a live writer.
        with self._reading_the_file(), self._db:
            self._db.execute("BEGIN")
            tightening = self._tightening
            every, runs, total = self._db.execute(
                f"SELECT COUNT(*), COALESCE(SUM({tightening}), 0), "
                "COALESCE(SUM(process_intensity), 0.0) FROM runs WHERE tool_id = ?",
                (tool_id,),
            ).fetchone()
            service = self._db.execute(
                "SELECT serviced_ns, note FROM services WHERE tool_id = ? "
                "ORDER BY serviced_ns DESC, id DESC LIMIT 1",
                (tool_id,),
            ).fetchone()
            since_ns = service[0] if service else None
            runs_since, total_since = self._db.execute(
                f"SELECT COALESCE(SUM({tightening}), 0), COALESCE(SUM(process_intensity), 0.0) "
                "FROM runs WHERE tool_id = ? AND ended_ns > ?",
                (tool_id, since_ns if since_ns is not None else -1),
            ).fetchone()
            worst = self._db.execute(
                "SELECT station, run_id, process_intensity, ended_ns FROM runs "
                "WHERE tool_id = ? ORDER BY process_intensity DESC, ended_ns LIMIT ?",
                (tool_id, WORST_RUNS),
            ).fetchall()
            stations = self._db.execute(
                "SELECT DISTINCT station FROM runs WHERE tool_id = ? ORDER BY station", (tool_id,)
            ).fetchall()
            controller = wear_tool_data.newest(self._db, tool_id)
            seen = self._outlook(tool_id, time.time_ns(), joints) if outlook else None
        return ToolWear(
            tool_id=tool_id,
            runs=int(runs),
            total_intensity=float(total),
            intensity_per_run=float(total) / every if every else 0.0,
            last_service_ns=since_ns,
            last_service_note=service[1] if service else None,
            runs_since_service=int(runs_since),
            intensity_since_service=float(total_since),
            worst_runs=[RunWear(str(s), int(r), float(i), int(e)) for s, r, i, e in worst],
            stations=[str(name) for (name,) in stations],
            controller=controller,
            loosenings=int(every) - int(runs),
            outlook=seen,
        )

    def outlook(
        self,
        tool_id: int,
        now_ns: int | None = None,
        joints: Mapping[tuple[str, int], str] | None = None,
        settings: ForecastSettings = SHIPPED,
    ) -> ToolOutlook | None:
        """The tool's outlook as of ``now_ns`` (default now: the runs and services up to
        then); None when it had no run by then."""
        with self._reading_the_file(), self._db:
            self._db.execute("BEGIN")
            return self._outlook(tool_id, now_ns or time.time_ns(), joints, settings)

    def _outlook(
        self,
        tool_id: int,
        now_ns: int,
        joints: Mapping[tuple[str, int], str] | None,
        settings: ForecastSettings = SHIPPED,
    ) -> ToolOutlook | None:
        """Inside a read transaction: :meth:`outlook`."""
        span = first_and_last(self._db, tool_id, now_ns)
        if span is None:
            return None
        service = self._db.execute(
            "SELECT MAX(serviced_ns) FROM services WHERE tool_id = ? AND serviced_ns <= ?",
            (tool_id, now_ns),
        ).fetchone()
        serviced_ns = None if service is None or service[0] is None else int(service[0])
        calendar = ledger_calendar(self._db, self.identity, now_ns)
        window_ns = now_ns - settings.window_days * DAY_NS
        from_ns = -1 if serviced_ns is None else min(serviced_ns, window_ns)
        groups = grouped_runs(
            self._db, tool_id, calendar, from_ns, serviced_ns, now_ns, self._tightening
        )
        seen = tool_outlook(
            groups, calendar, span[0], span[1], serviced_ns, now_ns, joints, settings
        )
        limits = run_limits(groups, calendar, now_ns)
        found = unusual_runs(self._db, tool_id, limits, calendar, serviced_ns, now_ns)
        return ToolOutlook(seen.pace, seen.calendar, seen.since_service, seen.causes, found)

    def close(self) -> None:
        self._db.close()

    def __enter__(self) -> WearLedger:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()
