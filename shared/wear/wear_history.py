"""What the forecast reads of the ledger's history: bounded reads, inside one read transaction.

- :func:`ledger_calendar`: the plant's production calendar
  (:func:`~.wear_calendar.learn_calendar`) from at most :data:`CALENDAR_SAMPLE`
  runs of the last :data:`CALENDAR_WEEKS` weeks, picked evenly by rowid (the
  ledger never deletes a run, so rowids run in the order written): a few
  thousand lookups on the table's own b-tree, however large the ledger. It is
  kept per ledger file for :data:`CALENDAR_KEPT_NS` (a calendar changes over
  weeks, not minutes).
- :func:`grouped_runs`: one tool's runs since the older of its last service and
  the pace's window, summed per production day, station and program on the
  tool's index (what :func:`~.wear_outlook.tool_outlook` makes its outlook of).
- :func:`unusual_runs`: the tool's runs of the recent days above their program's
  limit (:func:`~.wear_outlook.run_limits`).

Every read takes ``now_ns`` and leaves out what ended after it (a live ledger
holds nothing later; a backtest's holds the months it replays).
"""

from __future__ import annotations

import sqlite3
import threading
from collections.abc import Sequence

import numpy as np

from shared.wear.wear_calendar import DAY_NS, ProductionCalendar, learn_calendar
from shared.wear.wear_grouped_runs import GroupedRuns
from shared.wear.wear_outlook import MAX_UNUSUAL_RUNS, RECENT_DAYS, RunLimit, UnusualRun
from shared.wear.wear_since_service import TIGHTENING

#: the weeks of runs a calendar is learned from
CALENDAR_WEEKS = 8
#: at most this many runs read to learn it
CALENDAR_SAMPLE = 20_000
#: a calendar learned is used this long (of the ledger's clock, ``now_ns``)
CALENDAR_KEPT_NS = 6 * 3600 * 1_000_000_000

_kept: dict[tuple[int, int], tuple[int, ProductionCalendar | None]] = {}
_kept_lock = threading.Lock()


def ledger_calendar(
    db: sqlite3.Connection, identity: tuple[int, int], now_ns: int
) -> ProductionCalendar | None:
    """The calendar of the ledger file ``identity`` (device, inode) at ``now_ns``: learned
    again when the one kept is older than :data:`CALENDAR_KEPT_NS` (or from later)."""
    with _kept_lock:
        kept = _kept.get(identity)
    if kept is not None and 0 <= now_ns - kept[0] < CALENDAR_KEPT_NS:
        return kept[1]
    calendar = learn_calendar(run_times_sample(db, now_ns))
    with _kept_lock:
        _kept[identity] = (now_ns, calendar)
    return calendar


def run_times_sample(db: sqlite3.Connection, now_ns: int) -> np.ndarray:
    """The end times of at most :data:`CALENDAR_SAMPLE` runs of the last
    :data:`CALENDAR_WEEKS` weeks up to ``now_ns``, evenly spread over them."""
    (newest,) = db.execute("SELECT COALESCE(MAX(rowid), 0) FROM runs").fetchone()
    if newest == 0:
        return np.zeros(0, dtype=np.int64)
    since_ns = now_ns - CALENDAR_WEEKS * 7 * DAY_NS
    first = _first_rowid_ending_after(db, since_ns, newest)
    last = _first_rowid_ending_after(db, now_ns, newest) - 1
    if last < first:
        return np.zeros(0, dtype=np.int64)
    step = max(1, (last - first + 1) // CALENDAR_SAMPLE)
    rows = db.execute(
        "WITH RECURSIVE picks(r) AS (SELECT ? UNION ALL SELECT r + ? FROM picks WHERE r + ? <= ?) "
        "SELECT ended_ns FROM runs JOIN picks ON runs.rowid = picks.r",
        (first, step, step, last),
    ).fetchall()
    times = np.array([ended for (ended,) in rows], dtype=np.int64)
    return times[(times > since_ns) & (times <= now_ns)]


def _first_rowid_ending_after(db: sqlite3.Connection, time_ns: int, newest: int) -> int:
    """The first rowid whose run ended after ``time_ns`` (runs are written about in the order
    they end: bisection on rowid); ``newest + 1`` when none did."""
    low, high = 1, newest + 1
    while low < high:
        middle = (low + high) // 2
        row = db.execute(
            "SELECT ended_ns FROM runs WHERE rowid >= ? ORDER BY rowid LIMIT 1", (middle,)
        ).fetchone()
        if row is None or row[0] > time_ns:
            high = middle
        else:
            low = middle + 1
    return low


def grouped_runs(
    db: sqlite3.Connection,
    tool_id: int,
    calendar: ProductionCalendar | None,
    from_ns: int,
    last_service_ns: int | None,
    now_ns: int,
    tightening: str = TIGHTENING,
) -> list[GroupedRuns]:
    """The tool's runs that ended in (``from_ns``, ``now_ns``], summed per production day,
    station, program and whether after ``last_service_ns``."""
    day_start_ns = calendar.day_start_ns(0) if calendar is not None else 0
    rows = db.execute(
        f"SELECT (ended_ns - ?) / ?, station, program_id, ended_ns > ?, "
        f"SUM({tightening}), COUNT(*), SUM(process_intensity), "
        "SUM(process_intensity * process_intensity) FROM runs "
        "WHERE tool_id = ? AND ended_ns > ? AND ended_ns <= ? "
        "GROUP BY 1, 2, 3, 4",
        (
            day_start_ns,
            DAY_NS,
            -1 if last_service_ns is None else last_service_ns,
            tool_id,
            from_ns,
            now_ns,
        ),
    )
    return [
        GroupedRuns(int(day), str(station), int(program), bool(after), int(runs), int(every),
                    float(intensity), float(squares))
        for day, station, program, after, runs, every, intensity, squares in rows
    ]  # fmt: skip


def first_and_last(db: sqlite3.Connection, tool_id: int, now_ns: int) -> tuple[int, int] | None:
    """When the tool's first and newest runs up to ``now_ns`` ended; None: it has none."""
    # each an end of the tool's index (one lookup), not a scan of its runs
    first = db.execute(
        "SELECT ended_ns FROM runs WHERE tool_id = ? AND ended_ns <= ? ORDER BY ended_ns LIMIT 1",
        (tool_id, now_ns),
    ).fetchone()
    if first is None:
        return None
    last = db.execute(
        "SELECT ended_ns FROM runs WHERE tool_id = ? AND ended_ns <= ? "
        "ORDER BY ended_ns DESC LIMIT 1",
        (tool_id, now_ns),
    ).fetchone()
    return int(first[0]), int(last[0])


def unusual_runs(
    db: sqlite3.Connection,
    tool_id: int,
    limits: Sequence[RunLimit],
    calendar: ProductionCalendar | None,
    last_service_ns: int | None,
    now_ns: int,
) -> list[UnusualRun]:
    """The tool's runs since its service within the recent days that are above their
    program's limit at their station, the furthest above first."""
    if not limits:
        return []
    by_group = {(limit.station, limit.program_id): limit for limit in limits}
    recent_ns = (
        calendar.day_start_ns(calendar.day_of(now_ns) - RECENT_DAYS + 1)
        if calendar is not None
        else now_ns - RECENT_DAYS * DAY_NS
    )
    since_ns = max(recent_ns, -1 if last_service_ns is None else last_service_ns)
    rows = db.execute(
        "SELECT station, run_id, program_id, process_intensity, ended_ns FROM runs "
        "WHERE tool_id = ? AND ended_ns > ? AND ended_ns <= ? AND process_intensity > ?",
        (tool_id, since_ns, now_ns, min(limit.intensity for limit in limits)),
    )
    found = []
    for station, run_id, program, intensity, ended_ns in rows:
        limit = by_group.get((str(station), int(program)))
        if limit is not None and intensity > limit.intensity:
            found.append(
                UnusualRun(
                    str(station),
                    int(run_id),
                    int(program),
                    float(intensity),
                    int(ended_ns),
                    limit.history_per_run,
                    float(intensity) / limit.history_per_run,
                )
            )
    found.sort(key=lambda run: (-run.ratio, run.ended_ns))
    return found[:MAX_UNUSUAL_RUNS]
