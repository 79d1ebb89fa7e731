"""The wear ledger's file: made whole, recognised when broken, moved aside, never deleted.

A ledger is made under a temporary name (WAL mode, schema, boltwatch's
``application_id``) and linked into place when complete, so a file at the
ledger's path is always a finished ledger, never a half-made one: an empty
file there is damage, not a ledger in the making.

A file at the ledger's path is **broken** when it is empty, is not a SQLite
file, is another application's SQLite file or has another schema, or SQLite
finds it corrupt (:func:`is_broken_error`). Nothing writes into a broken
ledger (SQLite would take an empty file for a new database and an unknown
one for its own); :class:`BrokenLedgerError` says in one line what and what
to do: ``boltwatch wear reset`` moves it aside (:func:`move_aside`: the file
and its ``-wal`` and ``-shm`` as ``wear.sqlite.broken-<UTC stamp>[-wal|-shm]``,
kept, so SQLite still reads them together) and starts a new ledger.

The ledger's version is SQLite's ``PRAGMA user_version``
(:data:`LEDGER_VERSION`): 0 or 1 for a ledger of runs and services only, 2
with the ``tool_data`` table (:mod:`.wear_tool_data`), 3 with the runs'
``operation`` (a tightening or a loosening). A table or a last column that
came with a later version may be missing (the writer adds it, :func:`migrate`:
nothing of the file is lost; a reader takes every run of such a ledger for a
tightening, as the boltwatch that wrote it did); every table that is there
must have its columns; a ledger of a newer version than this boltwatch knows
is not written into.

Whether a process has the ledger open is what SQLite's WAL mode itself
shows (:func:`holder_pid`): every connection holds a read lock on the "DMS"
byte of the ``-shm`` file (offset 128, SQLite's ``UNIX_SHM_DMS``) for as
long as it is open.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import secrets
import sqlite3
import struct
from datetime import UTC, datetime
from pathlib import Path

from shared.errors import InputError
from shared.files import fsync_path
from shared.wear import wear_tool_data

#: The first 16 bytes of every SQLite 3 database file.
SQLITE_MAGIC = b"SQLite format 3\x00"
#: ``PRAGMA application_id`` of a boltwatch wear ledger: "bolt".
APPLICATION_ID = 0x626F6C74
#: SQLite's primary result codes for a damaged file: SQLITE_CORRUPT, SQLITE_NOTADB.
BROKEN_CODES = (11, 26)
#: Byte of the ``-shm`` file every open WAL connection read-locks (SQLite's UNIX_SHM_DMS).
SHM_DMS_OFFSET = 128
#: Companion files SQLite keeps beside a database in WAL mode.
COMPANIONS = ("-wal", "-shm")
#: Columns of the ledger's tables, in order (see :mod:`.wear_ledger`).
COLUMNS = {
    "runs": (
        "station", "run_id", "tool_id", "program_id", "tool_state", "stop_reason", "events",
        "process_intensity", "started_ns", "ended_ns", "recorded_ns", "operation",
    ),
    "services": ("id", "tool_id", "serviced_ns", "note"),
    wear_tool_data.TABLE: wear_tool_data.COLUMNS,
}  # fmt: skip
#: ``PRAGMA user_version`` of a ledger this boltwatch writes: 2 since the tool_data table,
#: 3 since the runs' operation
LEDGER_VERSION = 3
#: tables added by a later version (table -> its version): missing in an older ledger
ADDED_IN = {wear_tool_data.TABLE: 2}
#: last columns added by a later version (table -> (column, its definition)): missing in an
#: older ledger
ADDED_COLUMNS = {"runs": (("operation", "TEXT NOT NULL DEFAULT 'tightening'"),)}
_NEW_PREFIX = "new-"


class BrokenLedgerError(InputError):
    """The file at the ledger's path is no usable wear ledger; it takes a person to move it."""

    def __init__(self, path: Path, what: str) -> None:
        self.path = path
        self.what = what
        super().__init__(
            f"{path}: not a usable wear ledger: {what}; move it aside and start a new "
            f"ledger: boltwatch wear reset --recordings {path.parent}"
        )


def is_broken_error(err: sqlite3.Error) -> bool:
    """Whether SQLite's error says the file is damaged (not busy, full or read-only)."""
    code = getattr(err, "sqlite_errorcode", None)
    if code is not None and code & 0xFF in BROKEN_CODES:
        return True
    text = str(err)
    return text.startswith(("no such table", "no such column"))  # its tables went away


def file_problem(path: Path) -> str | None:
    """What is wrong with the file at ``path`` before SQLite opens it; None if nothing.

    A missing file is no problem here (a new ledger is made); OSError when it
    cannot be read.
    """
    try:
        with path.open("rb") as handle:
            head = handle.read(len(SQLITE_MAGIC))
    except FileNotFoundError:
        return None
    if not head:
        return "it is empty (0 bytes)"
    if head != SQLITE_MAGIC:
        return f"not a SQLite file (it starts with {head[:8]!r})"
    return None


def schema_problem(db: sqlite3.Connection) -> str | None:
    """What makes an open SQLite file no wear ledger; None when it is one."""
    (application_id,) = db.execute("PRAGMA application_id").fetchone()
    if application_id not in (0, APPLICATION_ID):  # 0: a ledger made before the id
        return f"another application's SQLite file (application_id {application_id:#x})"
    (version,) = db.execute("PRAGMA user_version").fetchone()
    if version > LEDGER_VERSION:
        return (
            f"a ledger of version {version}, newer than this boltwatch knows "
            f"({LEDGER_VERSION}): update boltwatch"
        )
    for table, expected in COLUMNS.items():
        columns = tuple(row[1] for row in db.execute(f"PRAGMA table_info({table})"))
        if not columns and table in ADDED_IN:
            continue  # an older ledger: the writer adds it (migrate)
        if not columns:
            return f"another schema: no table {table!r}"
        added = len(ADDED_COLUMNS.get(table, ()))
        if columns != expected and columns != expected[: len(expected) - added]:
            return f"another schema: table {table!r} has columns {', '.join(columns)}"
    return None


def has_column(db: sqlite3.Connection, table: str, column: str) -> bool:
    """Whether ``table`` of the open ledger has ``column`` (an older ledger may lack it)."""
    return any(row[1] == column for row in db.execute(f"PRAGMA table_info({table})"))


def migrate(db: sqlite3.Connection, schema: str) -> int | None:
    """Bring an open ledger (checked by :func:`schema_problem`) to :data:`LEDGER_VERSION`:
    the tables it lacks added from ``schema`` (``CREATE TABLE IF NOT EXISTS``), in one
    transaction; the version it had, or None when it was current."""
    (version,) = db.execute("PRAGMA user_version").fetchone()
    if version == LEDGER_VERSION:
        db.executescript(schema)  # nothing to add; indexes of a ledger made by hand
        return None
    columns = "".join(
        f"ALTER TABLE {table} ADD COLUMN {column} {definition}; "
        for table, added in ADDED_COLUMNS.items()
        for column, definition in added
        if not has_column(db, table, column)
    )
    db.executescript(f"BEGIN; {schema} {columns}PRAGMA user_version = {LEDGER_VERSION}; COMMIT;")
    return int(version)


def create_ledger(path: Path, schema: str) -> None:
    """Make a new ledger at ``path`` (WAL, ``schema``), whole or not at all.

    Made under a temporary name and hard-linked into place: if another
    process made one meanwhile, that one stays and this one is dropped.
    """
    remove_stale_temporaries(path)
    temporary = path.with_name(f".{path.name}.{_NEW_PREFIX}{os.getpid()}-{secrets.token_hex(4)}")
    try:
        db = sqlite3.connect(temporary)
        try:
            db.execute(f"PRAGMA application_id = {APPLICATION_ID}")
            db.execute(f"PRAGMA user_version = {LEDGER_VERSION}")
            db.execute("PRAGMA journal_mode=WAL")
            db.executescript(schema)
        finally:
            db.close()  # the WAL goes into the file: complete on its own
        with contextlib.suppress(FileExistsError):
            os.link(temporary, path)
        fsync_path(path.parent)
    finally:
        for name in (temporary, *(Path(f"{temporary}{end}") for end in COMPANIONS)):
            name.unlink(missing_ok=True)


def remove_stale_temporaries(path: Path) -> None:
    """Temporaries a process killed while making a ledger left (its pid is gone)."""
    for leftover in path.parent.glob(f".{path.name}.{_NEW_PREFIX}*"):
        pid_text = leftover.name.rsplit(_NEW_PREFIX, 1)[-1].split("-", 1)[0]
        if pid_text.isdigit() and not Path(f"/proc/{pid_text}").exists():
            leftover.unlink(missing_ok=True)


def identity(path: Path) -> tuple[int, int]:
    """(device, inode) of the file at ``path``: a different pair is a different file."""
    status = path.stat()
    return status.st_dev, status.st_ino


def holder_pid(path: Path) -> int | None:
    """The pid of a process that has the ledger open (SQLite's WAL lock), or None."""
    try:
        fd = os.open(f"{path}-shm", os.O_RDONLY)
    except FileNotFoundError:
        return None  # no -shm: no WAL connection anywhere
    try:
        query = struct.pack("hhqqi4x", fcntl.F_WRLCK, os.SEEK_SET, SHM_DMS_OFFSET, 1, 0)
        answer = fcntl.fcntl(fd, fcntl.F_GETLK, query)
    finally:
        os.close(fd)
    lock_type, _, _, _, pid = struct.unpack("hhqqi4x", answer)
    return None if lock_type == fcntl.F_UNLCK else int(pid)


def move_aside(path: Path, now: datetime | None = None) -> Path:
    """Rename the ledger and its companions to ``<name>.broken-<UTC stamp>``; the new name."""
    stamp = (now or datetime.now(UTC)).strftime("%Y%m%dT%H%M%SZ")
    target = path.with_name(f"{path.name}.broken-{stamp}")
    copy = 2
    while any(Path(f"{target}{end}").exists() for end in ("", *COMPANIONS)):
        target = path.with_name(f"{path.name}.broken-{stamp}-{copy}")
        copy += 1
    for end in COMPANIONS:  # kept under the same stem: SQLite reads them together
        with contextlib.suppress(FileNotFoundError):
            os.rename(f"{path}{end}", f"{target}{end}")
    os.rename(path, target)
    fsync_path(path.parent)
    return target
