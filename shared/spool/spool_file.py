"""The spool on disk: every message a station put toward the line, until the recorder has it.

One SQLite file per (station, source), WAL, ``synchronous=FULL``: a message
is kept once :meth:`SpoolFile.commit` returned (the caller commits in groups,
every :data:`COMMIT_INTERVAL_S` or :data:`COMMIT_ROWS` messages: a power cut
loses at most the messages of the group in progress, never an older one). A
message is its channel's topic, its encoded payload (zstd, level 1: JSON of
samples shrinks about six times), its kind and run. ``seq`` counts from 1 and
is never given twice, also after a restart or a delete (``AUTOINCREMENT``).
The file's :attr:`SpoolFile.spool_id`, drawn when it is made, tells a spool
made again (a deleted file, a new edge box) from the one before: its numbers
start from 1 again.

A message is put toward the line as soon as it is appended, before its group
is committed (the stop path waits for no disk). So a process killed, or a
power cut, loses the group in progress (at most :data:`COMMIT_ROWS`
messages, :data:`COMMIT_INTERVAL_S` of them) from the spool, though the
recorder may have some of them already; and their numbers must never be
given again, or the recorder would take new messages for ones it has. A file
not closed cleanly therefore skips :data:`COMMIT_ROWS` numbers when it is
opened again (:attr:`SpoolFile.skipped_at_open`): the recorder counts the
numbers it never got as gone. A group that fails to be written (a full disk:
SQLite rolls it back) is lost from the spool the same way: its numbers are
never given again (the next group starts past the highest given), the counts
are taken again from the file, and the spool works again as soon as the disk
takes writes.

Kinds: samples (a batch or a sample), records (a run's result, summary,
controller result: never dropped), others (tool states, events, decisions,
bus counters...). To keep the file under its bound, the oldest samples go
first, then the oldest others; records stay even past the bound (a run's
result is small and is what a quality engineer needs).
"""

from __future__ import annotations

import contextlib
import os
import secrets
import sqlite3
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Final

import zstandard

from shared.spool.seq_ranges import SeqRanges

#: a group of messages is committed (and fsynced) at least this often
COMMIT_INTERVAL_S: Final = 0.1
COMMIT_ROWS: Final = 500
SCHEMA_VERSION: Final = 1

KIND_SAMPLES: Final = 0
KIND_RECORDS: Final = 1
KIND_OTHER: Final = 2

_SCHEMA = """
CREATE TABLE IF NOT EXISTS spooled (
    seq INTEGER PRIMARY KEY AUTOINCREMENT,
    topic TEXT NOT NULL,
    kind INTEGER NOT NULL,
    run_id INTEGER,
    samples INTEGER NOT NULL,
    put_ns INTEGER NOT NULL,
    payload BLOB NOT NULL
);
CREATE INDEX IF NOT EXISTS spooled_kind ON spooled (kind, seq);
CREATE TABLE IF NOT EXISTS counters (name TEXT PRIMARY KEY, value INTEGER NOT NULL);
"""


@dataclass(frozen=True, slots=True)
class Spooled:
    """One message as it was put: its number, channel topic and payload."""

    seq: int
    topic: str
    payload: bytes
    put_ns: int
    kept_before: int  # the seq the spool holds before it (0: none): those between are gone


@dataclass(frozen=True, slots=True)
class SpoolDepth:
    """What waits in the spool."""

    messages: int
    samples: int
    runs: int
    oldest_seq: int  # 0: empty
    oldest_run_id: int | None
    oldest_ns: int | None
    file_bytes: int


class SpoolFile:
    """A station's spool file (one writer: the station's publisher thread)."""

    def __init__(self, path: Path) -> None:
        path.parent.mkdir(parents=True, exist_ok=True)
        self.path = path
        self._db = sqlite3.connect(path, isolation_level=None, check_same_thread=False)
        self._db.execute("PRAGMA journal_mode=WAL")
        self._db.execute("PRAGMA synchronous=FULL")
        self._db.executescript(_SCHEMA)
        self._db.execute(f"PRAGMA user_version={SCHEMA_VERSION}")
        self._compress = zstandard.ZstdCompressor(level=1).compress
        self._decompress = zstandard.ZstdDecompressor().decompress
        self.uncommitted = 0
        #: the highest seq given: a group rolled back must not make SQLite give its again
        self._given_seq = 0
        self._failed = False  # a write failed: the next group starts past ``_given_seq``
        # what is kept, counted as it changes (one scan at the start, none after)
        self.messages = self.samples = self.stored_bytes = 0
        self._runs: Counter[int] = Counter()
        self._count("1 = 1", (), sign=+1)
        self.spool_id = self.counter("spool_id")
        if not self.spool_id:
            self.spool_id = self.add_counter("spool_id", secrets.randbelow(2**48) + 1)
        self.skipped_at_open = self._skip_if_unclean()

    def close(self) -> None:
        """Commit what is pending and close (cleanly: no number skipped at the next open);
        safe to call twice."""
        with contextlib.suppress(sqlite3.ProgrammingError):  # closed already
            # a disk that takes no write: the group is lost, the file left as not closed
            # cleanly (the next open skips numbers)
            with contextlib.suppress(sqlite3.OperationalError):
                self.commit()
                self._db.execute("UPDATE counters SET value = 0 WHERE name = 'open'")
            self._db.close()

    def _skip_if_unclean(self) -> int:
        """Mark the file open; when it was not closed cleanly, skip the numbers the group in
        progress may have used (their messages may have reached the recorder); how many."""
        skipped = 0
        if self.counter("open"):
            skipped = COMMIT_ROWS
            head = self.head_seq + skipped
            if not self._db.execute(
                "SELECT 1 FROM sqlite_sequence WHERE name = 'spooled'"
            ).fetchone():
                self._db.execute("INSERT INTO sqlite_sequence (name, seq) VALUES ('spooled', 0)")
            self._db.execute("UPDATE sqlite_sequence SET seq = ? WHERE name = 'spooled'", (head,))
        self._db.execute("INSERT OR REPLACE INTO counters (name, value) VALUES ('open', 1)")
        return skipped

    # -- writing -------------------------------------------------------------------------

    def append(
        self, topic: str, payload: bytes, kind: int, run_id: int | None, samples: int, put_ns: int
    ) -> int:
        """Keep one message; its seq. Durable after the next :meth:`commit`. A write that
        fails (sqlite3.Error: a full disk) loses the group in progress, whose seqs are
        never given again."""
        stored = self._compress(payload)
        try:
            if not self._db.in_transaction:
                self._db.execute("BEGIN")
                if self._failed:
                    self._skip_given()
            cursor = self._db.execute(
                "INSERT INTO spooled (topic, kind, run_id, samples, put_ns, payload) "
                "VALUES (?, ?, ?, ?, ?, ?)",
                (topic, kind, run_id, samples, put_ns, stored),
            )
        except sqlite3.Error:
            self._group_lost()
            raise
        self.uncommitted += 1
        self.messages += 1
        self.samples += samples
        self.stored_bytes += len(stored)
        if run_id is not None:
            self._runs[run_id] += 1
        seq = cursor.lastrowid
        assert seq is not None
        self._given_seq = max(self._given_seq, seq)
        return seq

    def commit(self) -> None:
        """What was appended reaches the disk (fsync); sqlite3.Error when it cannot (the group
        is lost, :meth:`append` starts the next one)."""
        if self._db.in_transaction:
            try:
                self._db.execute("COMMIT")
            except sqlite3.Error:
                self._group_lost()
                raise
        self.uncommitted = 0

    def _group_lost(self) -> None:
        """A write failed: the group in progress is rolled back (SQLite may have done it),
        what is kept counted again from the file, its seqs skipped by the next group."""
        with contextlib.suppress(sqlite3.Error):
            if self._db.in_transaction:
                self._db.execute("ROLLBACK")
        self._failed = True
        self.uncommitted = 0
        self.messages = self.samples = self.stored_bytes = 0
        self._runs.clear()
        with contextlib.suppress(sqlite3.Error):
            self._count("1 = 1", (), sign=+1)

    def _skip_given(self) -> None:
        """In the group being begun: SQLite gives seqs past every one given before."""
        if self._given_seq > self.head_seq:
            if not self._db.execute(
                "SELECT 1 FROM sqlite_sequence WHERE name = 'spooled'"
            ).fetchone():
                self._db.execute("INSERT INTO sqlite_sequence (name, seq) VALUES ('spooled', 0)")
            self._db.execute(
                "UPDATE sqlite_sequence SET seq = ? WHERE name = 'spooled'", (self._given_seq,)
            )
        self._failed = False

    def delete(self, ranges: Iterable[tuple[int, int]]) -> int:
        """Forget the messages of ``ranges`` (the recorder has them); how many."""
        deleted = 0
        for first, last in ranges:
            where, params = "seq BETWEEN ? AND ?", (first, last)
            self._count(where, params, sign=-1)
            deleted += self._db.execute(f"DELETE FROM spooled WHERE {where}", params).rowcount
        return deleted

    def drop_oldest(self, kind: int, count: int) -> tuple[int, int]:
        """Drop the ``count`` oldest messages of ``kind``; (messages, samples) dropped."""
        rows = self._db.execute(
            "SELECT seq, samples FROM spooled WHERE kind = ? ORDER BY seq LIMIT ?", (kind, count)
        ).fetchall()
        if not rows:
            return 0, 0
        where, params = "kind = ? AND seq <= ?", (kind, rows[-1][0])
        self._count(where, params, sign=-1)
        self._db.execute(f"DELETE FROM spooled WHERE {where}", params)
        return len(rows), sum(samples for _, samples in rows)

    def _count(self, where: str, params: tuple[int, ...], sign: int) -> None:
        """Add (``sign`` +1) or take away (-1) the messages ``where`` selects from the counts."""
        for run_id, messages, samples, stored in self._db.execute(
            "SELECT run_id, count(*), coalesce(sum(samples), 0), "
            f"coalesce(sum(length(payload)), 0) FROM spooled WHERE {where} GROUP BY run_id",
            params,
        ):
            self.messages += sign * messages
            self.samples += sign * samples
            self.stored_bytes += sign * stored
            if run_id is not None:
                self._runs[run_id] += sign * messages
                if self._runs[run_id] <= 0:
                    del self._runs[run_id]

    def add_counter(self, name: str, amount: int) -> int:
        """A counter kept in the file (what was dropped, across restarts); its new value."""
        self._db.execute(
            "INSERT INTO counters (name, value) VALUES (?, ?) "
            "ON CONFLICT (name) DO UPDATE SET value = value + excluded.value",
            (name, amount),
        )
        return self.counter(name)

    def counter(self, name: str) -> int:
        row = self._db.execute("SELECT value FROM counters WHERE name = ?", (name,)).fetchone()
        return int(row[0]) if row else 0

    # -- reading -------------------------------------------------------------------------

    def after(self, seq: int, limit: int, put_before_ns: int, skip: SeqRanges) -> list[Spooled]:
        """Up to ``limit`` messages after ``seq``, oldest first, as far as they were put before
        ``put_before_ns``, leaving out those in ``skip`` (the recorder has them)."""
        found: list[Spooled] = []
        row = self._db.execute("SELECT max(seq) FROM spooled WHERE seq <= ?", (seq,)).fetchone()
        cursor = seq
        previous = int(row[0]) if row and row[0] is not None else 0
        while len(found) < limit:
            rows = self._db.execute(
                "SELECT seq, topic, payload, put_ns FROM spooled WHERE seq > ? "
                "ORDER BY seq LIMIT ?",
                (cursor, limit),
            ).fetchall()
            if not rows:
                break
            for row_seq, topic, payload, put_ns in rows:
                if put_ns >= put_before_ns:  # too new: the pass goes no further
                    return found
                cursor = row_seq
                if row_seq not in skip:
                    message = Spooled(row_seq, topic, self._decompress(payload), put_ns, previous)
                    found.append(message)
                previous = row_seq
                if len(found) == limit:
                    break
        return found

    @property
    def head_seq(self) -> int:
        """The newest seq ever given (0: none)."""
        row = self._db.execute("SELECT seq FROM sqlite_sequence WHERE name = 'spooled'").fetchone()
        return int(row[0]) if row else 0

    def depth(self) -> SpoolDepth:
        """What waits (counted as it changed; the oldest message looked up by its seq)."""
        oldest = self._db.execute("SELECT seq, put_ns FROM spooled ORDER BY seq LIMIT 1").fetchone()
        oldest_run = self._db.execute(
            "SELECT run_id FROM spooled WHERE run_id IS NOT NULL ORDER BY seq LIMIT 1"
        ).fetchone()
        return SpoolDepth(
            self.messages,
            self.samples,
            len(self._runs),
            oldest[0] if oldest else 0,
            oldest_run[0] if oldest_run else None,
            oldest[1] if oldest else None,
            self.file_bytes(),
        )

    def file_bytes(self) -> int:
        """The spool's size on disk: the file and its WAL."""
        total = 0
        for suffix in ("", "-wal"):
            with contextlib.suppress(FileNotFoundError):
                total += os.stat(f"{self.path}{suffix}").st_size
        return total
