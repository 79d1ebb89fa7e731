"""What controllers said of the ledger's tools: the ``tool_data`` table of the wear ledger.

A :class:`~shared.contract.messages.ToolData` (a controller bridge's, Open Protocol
MID 0041) is kept per (station, tool_id), the newest by receive time: the
tool's serial (what makes the station's tool id a tool of the plant), the
controller's serial and software, its own tightening counters, the last
calibration and service dates it keeps. A tool's line of the ledger carries
the newest of its stations' (:class:`ControllerTool`).

The table came with ledger version 2 (:data:`~.wear_ledger_file.LEDGER_VERSION`):
a ledger made before it has none until a recorder opens it for writing and
adds it (its runs and services untouched); a reader of such a ledger sees no
tool data.
"""

from __future__ import annotations

import sqlite3
from dataclasses import dataclass
from typing import Any

from shared.contract import ToolData

TABLE = "tool_data"
#: its columns, in order (checked by :func:`~.wear_ledger_file.schema_problem`)
COLUMNS = (
    "station", "tool_id", "tool_serial", "controller_serial", "tightenings",
    "tightenings_since_service", "last_calibration_ns", "last_service_ns",
    "calibration_value_nm", "tool_type", "tool_model", "controller_software", "received_ns",
    "recorded_ns",
)  # fmt: skip

SCHEMA = f"""
CREATE TABLE IF NOT EXISTS {TABLE} (
    station TEXT NOT NULL,
    tool_id INTEGER NOT NULL,
    tool_serial TEXT NOT NULL,
    controller_serial TEXT,
    tightenings INTEGER,
    tightenings_since_service INTEGER,
    last_calibration_ns INTEGER,
    last_service_ns INTEGER,
    calibration_value_nm REAL,
    tool_type TEXT,
    tool_model TEXT,
    controller_software TEXT,
    received_ns INTEGER NOT NULL,
    recorded_ns INTEGER NOT NULL,
    PRIMARY KEY (station, tool_id)
);
"""

_UPDATED = ", ".join(f"{name} = excluded.{name}" for name in COLUMNS[2:])
_STORE = (
    f"INSERT INTO {TABLE} VALUES ({', '.join('?' * len(COLUMNS))}) "
    f"ON CONFLICT (station, tool_id) DO UPDATE SET {_UPDATED} "
    f"WHERE excluded.received_ns >= {TABLE}.received_ns"
)


@dataclass(frozen=True, slots=True)
class ControllerTool:
    """The newest of what a controller said of a tool (None: it did not say)."""

    station: str  # where it was said
    tool_serial: str
    controller_serial: str | None
    tightenings: int | None  # the controller's count of the tool's tightenings
    tightenings_since_service: int | None
    last_calibration_ns: int | None
    last_service_ns: int | None  # the controller's date of the tool's last service
    calibration_value_nm: float | None
    tool_type: str | None
    tool_model: str | None
    controller_software: str | None
    received_ns: int  # when the bridge received it

    @classmethod
    def from_dict(cls, fields: dict[str, Any]) -> ControllerTool:
        return cls(**fields)


def store(db: sqlite3.Connection, data: ToolData, recorded_ns: int) -> bool:
    """Keep ``data`` for its (station, tool_id) unless a newer one is kept; True if kept."""
    with db:
        cursor = db.execute(
            _STORE,
            (
                data.station,
                data.tool_id,
                data.tool_serial,
                data.controller_serial,
                data.tightenings,
                data.tightenings_since_service,
                data.last_calibration_ns,
                data.last_service_ns,
                data.calibration_value_nm,
                data.tool_type,
                data.tool_model,
                data.controller_software,
                data.time_ns,
                recorded_ns,
            ),
        )
    return cursor.rowcount == 1


def has_table(db: sqlite3.Connection) -> bool:
    """Whether the ledger has the table (a ledger before version 2 read as it is: not)."""
    row = db.execute("SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = ?", (TABLE,))
    return row.fetchone() is not None


def newest(db: sqlite3.Connection, tool_id: int) -> ControllerTool | None:
    """What the newest controller said of ``tool_id`` at any station, or None."""
    if not has_table(db):
        return None
    row = db.execute(
        f"SELECT station, tool_serial, controller_serial, tightenings, "
        f"tightenings_since_service, last_calibration_ns, last_service_ns, "
        f"calibration_value_nm, tool_type, tool_model, controller_software, received_ns "
        f"FROM {TABLE} WHERE tool_id = ? ORDER BY received_ns DESC, station LIMIT 1",
        (tool_id,),
    ).fetchone()
    return None if row is None else ControllerTool(*row)


def tool_ids(db: sqlite3.Connection, station: str | None) -> list[int]:
    """The tools controllers spoke of (at ``station``)."""
    if not has_table(db):
        return []
    if station is None:
        rows = db.execute(f"SELECT DISTINCT tool_id FROM {TABLE}")
    else:
        rows = db.execute(f"SELECT DISTINCT tool_id FROM {TABLE} WHERE station = ?", (station,))
    return [int(tool_id) for (tool_id,) in rows]
