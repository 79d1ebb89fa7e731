"""A tool's runs and intensity since its last service, kept without reading its history again.

The recorder asks after every run it counts when a service threshold is set
(:mod:`.wear_watch`: the alert compares the intensity since service with it).
Summing the tool's runs each time reads its whole interval: a year of one
tool's runs (10^5) is milliseconds per run on the line server's one worker,
growing with every run. :class:`SinceServiceTally` reads a tool's interval
once (per tool and per service), then only the rows added since it last
looked, found by rowid: the ledger never deletes a run, so its rowids stay
1, 2, 3, ... in the order written and a new row's is above every other.

Exact with other writers on the same file (a second recorder, an import):
whatever they add is read the same way. A service recorded anywhere starts
the interval again; rowids below the last one read (a file rebuilt by hand)
read the interval whole.
"""

from __future__ import annotations

import sqlite3
from dataclasses import dataclass

#: SQL true for a run that is a tightening (not a loosening)
TIGHTENING = "operation = 'tightening'"
#: a tool's tightenings and the intensity of all its runs since a service, found by the
#: tool's index; bounded by rowid so the next read starts there (tool_id, since_ns, up to
#: rowid)
WHOLE_INTERVAL = (
    f"SELECT COALESCE(SUM({TIGHTENING}), 0), COALESCE(SUM(process_intensity), 0.0) FROM runs "
    "WHERE tool_id = ? AND ended_ns > ? AND rowid <= ?"
)
#: the same among the rows added since (from rowid, up to rowid, tool_id, since_ns);
#: ``+tool_id`` keeps SQLite on the rowids rather than the tool's whole index
ADDED_SINCE = (
    f"SELECT COALESCE(SUM({TIGHTENING}), 0), COALESCE(SUM(process_intensity), 0.0) FROM runs "
    "WHERE rowid > ? AND rowid <= ? AND +tool_id = ? AND ended_ns > ?"
)


@dataclass(frozen=True, slots=True)
class ServiceInterval:
    """One tool since its last service (since its first run when never serviced)."""

    tool_id: int
    last_service_ns: int | None
    runs: int  # its tightenings that ended after the service
    intensity: float  # Σ I_process of the runs (loosenings too) that ended after the service


@dataclass(frozen=True, slots=True)
class _Read:
    interval: ServiceInterval
    service_id: int | None  # the services row it starts at
    up_to_rowid: int  # every run row up to this one is in it


class SinceServiceTally:
    """Per tool, its :class:`ServiceInterval` and how far into the runs it has read."""

    def __init__(self, tightening: str = TIGHTENING) -> None:
        """``tightening``: SQL true for a tightening ("1" in a ledger before operations)."""
        self._reads: dict[int, _Read] = {}
        self._whole = WHOLE_INTERVAL.replace(TIGHTENING, tightening)
        self._added = ADDED_SINCE.replace(TIGHTENING, tightening)

    def interval(self, db: sqlite3.Connection, tool_id: int) -> ServiceInterval:
        """The tool's interval now; call inside one read transaction of ``db``."""
        service = db.execute(
            "SELECT id, serviced_ns FROM services WHERE tool_id = ? "
            "ORDER BY serviced_ns DESC, id DESC LIMIT 1",
            (tool_id,),
        ).fetchone()
        service_id, since_ns = (int(service[0]), int(service[1])) if service else (None, None)
        after_ns = -1 if since_ns is None else since_ns
        (newest_rowid,) = db.execute("SELECT COALESCE(MAX(rowid), 0) FROM runs").fetchone()
        before = self._reads.get(tool_id)
        if before is None or before.service_id != service_id or before.up_to_rowid > newest_rowid:
            runs, intensity = db.execute(self._whole, (tool_id, after_ns, newest_rowid)).fetchone()
            counted = ServiceInterval(tool_id, since_ns, int(runs), float(intensity))
        else:
            runs, intensity = db.execute(
                self._added, (before.up_to_rowid, newest_rowid, tool_id, after_ns)
            ).fetchone()
            was = before.interval
            counted = ServiceInterval(
                tool_id, since_ns, was.runs + int(runs), was.intensity + float(intensity)
            )
        self._reads[tool_id] = _Read(counted, service_id, int(newest_rowid))
        return counted
