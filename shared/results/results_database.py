"""One connection to a results store, SQLite or PostgreSQL, spoken the same way.

The store's SQL is written once, with ``?`` for parameters and types both
databases take (``BIGINT``, ``DOUBLE PRECISION``, ``TEXT``,
``INSERT ... ON CONFLICT DO NOTHING``); :class:`ResultsDatabase` turns ``?``
into psycopg's ``%s`` for PostgreSQL. Where the store is comes from one value
(:func:`store_target`, :func:`station_store`): none, the SQLite file ``results.sqlite`` in the
recordings folder (WAL, ``synchronous=FULL``: a result the recorder wrote
survives a power cut); a ``postgresql://`` URL, a plant's server that every
line's recorder writes into (libpq's own settings apply: ``PGPASSFILE`` for
the password, ``sslmode`` in the URL).

Connection failures and SQL errors of either database surface as
:class:`StoreError` with the store's name (never its password) and what
failed, so the recorder can wait and try again and a command can say it in
one line.
"""

from __future__ import annotations

import contextlib
import re
import sqlite3
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import psycopg

from shared.errors import StoreError
from shared.files import real_path

if TYPE_CHECKING:
    from shared.config import AnyStation

#: the SQLite store's file in the recordings folder
SQLITE_FILE = "results.sqlite"
#: how long a SQLite connection waits for another writer's lock (the recorder and a
#: ``results rebuild`` may write at once)
SQLITE_BUSY_TIMEOUT_S = 10.0
#: how long opening a PostgreSQL connection may take
CONNECT_TIMEOUT_S = 5
POSTGRES_SCHEMES = ("postgresql://", "postgres://")

Dialect = Literal["sqlite", "postgresql"]


@dataclass(frozen=True, slots=True)
class StoreTarget:
    """Where a results store is: a SQLite file or a PostgreSQL URL."""

    sqlite_path: Path | None = None
    postgres_url: str | None = None

    @property
    def dialect(self) -> Dialect:
        return "sqlite" if self.sqlite_path is not None else "postgresql"

    def __str__(self) -> str:
        if self.sqlite_path is not None:
            return str(self.sqlite_path)
        return without_password(self.postgres_url or "")


def store_target(recordings_folder: Path, database: str | None) -> StoreTarget:
    """The store of a station file: ``database`` (``[recorder] results_database``) or,
    when none, ``results.sqlite`` in its recordings folder."""
    if database is None:
        return StoreTarget(sqlite_path=recordings_folder / SQLITE_FILE)
    return postgres_target(database)


def station_store(station: AnyStation) -> StoreTarget:
    """The results store a loaded station file names (its recordings folder resolved)."""
    database = station.config.recorder.results_database
    return store_target(real_path(station.recordings_folder), database)


def postgres_target(url: str) -> StoreTarget:
    """A PostgreSQL store by its URL; ValueError when it is not a ``postgresql://`` one."""
    if not url.startswith(POSTGRES_SCHEMES):
        raise ValueError(f"not a postgresql:// URL: {without_password(url)!r}")
    return StoreTarget(postgres_url=url)


def without_password(url: str) -> str:
    """``url`` with the password of its user part replaced by ``***``."""
    return re.sub(r"(://[^:/@]+):[^@]*@", r"\1:***@", url)


class ResultsDatabase:
    """One open connection; every statement in a transaction of :meth:`transaction`."""

    def __init__(self, target: StoreTarget, application: str = "boltwatch") -> None:
        self.target = target
        self.dialect: Dialect = target.dialect
        self._sqlite: sqlite3.Connection | None = None
        self._postgres: psycopg.Connection[Any] | None = None
        try:
            if target.sqlite_path is not None:
                self._sqlite = _open_sqlite(target.sqlite_path)
            else:
                self._postgres = psycopg.connect(
                    target.postgres_url or "",
                    autocommit=True,
                    connect_timeout=CONNECT_TIMEOUT_S,
                    application_name=application,
                )
        except (OSError, sqlite3.Error, psycopg.Error) as err:
            raise StoreError(f"results store {target}: cannot open: {one_line(err)}") from err

    def close(self) -> None:
        with contextlib.suppress(sqlite3.Error, psycopg.Error):
            if self._sqlite is not None:
                self._sqlite.close()
            if self._postgres is not None:
                self._postgres.close()

    def __enter__(self) -> ResultsDatabase:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @contextlib.contextmanager
    def transaction(self, lock: bool = False) -> Iterator[None]:
        """One transaction: committed on leaving, rolled back on an error (a StoreError).
        ``lock``: one writer at a time from the start (migrations)."""
        try:
            if self._sqlite is not None:
                self._sqlite.execute("BEGIN IMMEDIATE" if lock else "BEGIN")
                try:
                    yield
                except BaseException:
                    self._sqlite.rollback()
                    raise
                self._sqlite.commit()
            else:
                assert self._postgres is not None
                with self._postgres.transaction():
                    if lock:  # "bolt": the same number in every boltwatch, the store's lock
                        self._postgres.execute("SELECT pg_advisory_xact_lock(1651469428)")
                    yield
        except (sqlite3.Error, psycopg.Error) as err:
            raise StoreError(f"results store {self.target}: {one_line(err)}") from err

    @contextlib.contextmanager
    def not_waiting(self) -> Iterator[None]:
        """SQLite: a lock another connection holds fails at once (a StoreError), instead of
        being waited for :data:`SQLITE_BUSY_TIMEOUT_S` (a reader's optional write)."""
        if self._sqlite is None:
            yield
            return
        self._sqlite.execute("PRAGMA busy_timeout = 0")
        try:
            yield
        finally:
            self._sqlite.execute(f"PRAGMA busy_timeout = {int(SQLITE_BUSY_TIMEOUT_S * 1000)}")

    def execute(self, sql: str, parameters: Sequence[Any] = ()) -> int:
        """Run one statement; the number of rows it changed."""
        return self._run(sql, parameters).rowcount

    def execute_many(self, sql: str, rows: Sequence[Sequence[Any]]) -> None:
        if not rows:
            return
        try:
            if self._sqlite is not None:
                self._sqlite.executemany(sql, rows)
            else:
                assert self._postgres is not None
                with self._postgres.cursor() as cursor:
                    cursor.executemany(self._sql(sql), rows)
        except (sqlite3.Error, psycopg.Error) as err:
            raise StoreError(f"results store {self.target}: {one_line(err)}") from err

    def rows(self, sql: str, parameters: Sequence[Any] = ()) -> list[tuple[Any, ...]]:
        """Every row a query gives (from PostgreSQL in its binary format: a month's figures
        came a fifth faster than as text)."""
        return list(self._run(sql, parameters, binary=True).fetchall())

    def row_batches(
        self, sql: str, parameters: Sequence[Any], batch_rows: int
    ) -> Iterator[list[tuple[Any, ...]]]:
        """The rows a query gives, ``batch_rows`` at a time (PostgreSQL's in its binary
        format): a long scan made into Python a part at a time."""
        cursor = self._run(sql, parameters, binary=True)
        while True:
            try:
                batch = cursor.fetchmany(batch_rows)
            except (sqlite3.Error, psycopg.Error) as err:
                raise StoreError(f"results store {self.target}: {one_line(err)}") from err
            if not batch:
                return
            yield list(batch)

    def _run(self, sql: str, parameters: Sequence[Any], binary: bool = False) -> Any:
        try:
            if self._sqlite is not None:
                return self._sqlite.execute(sql, parameters)
            assert self._postgres is not None
            return self._postgres.execute(self._sql(sql), parameters, binary=binary)
        except (sqlite3.Error, psycopg.Error) as err:
            raise StoreError(f"results store {self.target}: {one_line(err)}") from err

    def _sql(self, sql: str) -> str:
        """``?`` as psycopg's ``%s`` (the store's SQL has no ``?``, ``%`` in text)."""
        return sql.replace("?", "%s")


def _open_sqlite(path: Path) -> sqlite3.Connection:
    path.parent.mkdir(parents=True, exist_ok=True)
    connection = sqlite3.connect(
        path, timeout=SQLITE_BUSY_TIMEOUT_S, isolation_level=None, check_same_thread=False
    )
    try:
        _wal_mode(connection)
        connection.execute("PRAGMA synchronous=FULL")
    except sqlite3.Error:
        connection.close()
        raise
    return connection


def _wal_mode(connection: sqlite3.Connection) -> None:
    """WAL mode, asked again while another connection holds the lock: SQLite answers "database
    is locked" at once, without its busy handler, to a change of journal mode that meets one
    (several writers opening a new store together)."""
    deadline_s = time.monotonic() + SQLITE_BUSY_TIMEOUT_S
    while True:
        try:
            connection.execute("PRAGMA journal_mode=WAL")
            return
        except sqlite3.OperationalError as err:
            if "locked" not in str(err) or time.monotonic() > deadline_s:
                raise
            time.sleep(0.01)


def one_line(err: BaseException) -> str:
    """An error's text on one line (psycopg's span several)."""
    return " ".join(str(err).split()) or type(err).__name__
