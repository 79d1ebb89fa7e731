"""The SQLite store's planner statistics, kept by its writer (and written by a reader that
finds none): :func:`keep_statistics`.

SQLite picks an index by its statistics (the ``sqlite_stat1`` table). With
none, it guesses that an index's first column is selective: for a month of a
20-station line (``station IN (...) AND ended_ns`` in the month) it read the
month through the station index, once per station, and a month's report took
7.4 s of 10 million results; with statistics it reads the time index, once.

``ANALYZE`` computes them by reading every index: 86 s for 10 million
results (a cold cache), a pause no recorder should make.
``PRAGMA analysis_limit`` makes it quick by reading a few pages of each index,
and then finds about a hundred rows per station (there were half a million):
it sees a few keys and takes them as all. The store's rows have a shape known
beforehand, so its writer writes ``sqlite_stat1`` itself, as SQLite's
documentation allows (https://sqlite.org/fileformat2.html#stat1tab), for the
``tightenings`` table:

- its rows: the table's largest rowid (rows are deleted only by the migration
  to version 4, which moves the few a reader may not count aside);
- each index's rows per value of its first column: the rows over the number
  of values, counted by one index seek a value (20 stations: 20 seeks, about
  a millisecond); beyond :data:`SEEKS` values (a part, a time), the rows per
  value of the newest :data:`SAMPLE_ROWS` rows;
- the index's further columns (an end time, a run id) find one row.

They are written at the writer's open and again whenever the rows have
doubled since or an index has none (one made by a later migration), in one
short transaction. A store only readers open (a ``results rebuild`` of an
older boltwatch, a copy of a line's store given to ``report``) would plan
with SQLite's guesses until a recorder opens it: a reader that finds none
(:func:`statistics_missing`) writes them, when the file is writable and no
writer holds the store (it waits for none; the next reader tries again).
A store of fewer than :data:`FEWEST_ROWS` rows keeps SQLite's guesses (any
plan is quick there), and so does an index on an expression (none of the
store's own). The writer takes them as best effort:
a failure is logged and tried again later, its results stored all the same
(:class:`~.results_store.ResultsStore`).
Each connection opened after reads them; PostgreSQL keeps its own
(autovacuum's ``ANALYZE``).
"""

from __future__ import annotations

from shared.results.results_database import ResultsDatabase

#: the table whose statistics are kept
TABLE = "tightenings"
#: at most this many seeks for the values of an index's first column
SEEKS = 1000
#: the newest rows a column of more values is judged by
SAMPLE_ROWS = 1000
#: below this many rows, no statistics are written
FEWEST_ROWS = 1000


def keep_statistics(database: ResultsDatabase) -> int:
    """Write the statistics of a SQLite store when it has none or its rows have doubled
    since; the rows its statistics stand for (0: none, too few rows or not SQLite)."""
    if database.dialect != "sqlite":
        return 0
    with database.transaction(lock=True):
        rows, indexes = _rows_and_indexes(database)
        if rows < FEWEST_ROWS:
            return 0
        written, described = _written_for(database)
        if written and rows < 2 * written and described >= set(indexes):
            return written
        lines = [(name, _index_stat(database, columns, rows)) for name, columns in indexes.items()]
        database.execute("ANALYZE sqlite_schema")  # makes sqlite_stat1 where there is none
        database.execute("DELETE FROM sqlite_stat1 WHERE tbl = ?", (TABLE,))
        database.execute_many(
            "INSERT INTO sqlite_stat1 (tbl, idx, stat) VALUES (?, ?, ?)",
            [(TABLE, name, stat) for name, stat in lines],
        )
        database.execute("ANALYZE sqlite_schema")  # this connection plans with them too
    return int(rows)


def statistics_missing(database: ResultsDatabase) -> bool:
    """Whether a SQLite store of :data:`FEWEST_ROWS` rows or more has no statistics, or none
    of an index: what a reader looks at (without a lock) before it writes them."""
    if database.dialect != "sqlite":
        return False
    with database.transaction():
        rows, indexes = _rows_and_indexes(database)
        if rows < FEWEST_ROWS:
            return False
        written, described = _written_for(database)
    return not written or not described >= set(indexes)


def statistics_rows(database: ResultsDatabase) -> int:
    """The rows the store's statistics were written for (0: none)."""
    with database.transaction():
        return _written_for(database)[0]


def _written_for(database: ResultsDatabase) -> tuple[int, set[str]]:
    """The rows the statistics were written for (0: none), and the indexes they describe."""
    if not database.rows("SELECT name FROM sqlite_master WHERE name = 'sqlite_stat1'"):
        return 0, set()
    found = database.rows(
        "SELECT idx, stat FROM sqlite_stat1 WHERE tbl = ? AND idx IS NOT NULL", (TABLE,)
    )
    return (int(found[0][1].split()[0]) if found else 0), {name for name, _stat in found}


def _rows_and_indexes(database: ResultsDatabase) -> tuple[int, dict[str, list[str | None]]]:
    """The table's rows (its largest rowid), and the columns of each of its indexes that is
    not on an expression."""
    ((rows,),) = database.rows(f"SELECT COALESCE(MAX(rowid), 0) FROM {TABLE}")
    indexes = {
        name: columns
        for (name,) in database.rows(
            "SELECT name FROM sqlite_master WHERE type = 'index' AND tbl_name = ?", (TABLE,)
        )
        if None not in (columns := _columns(database, name))  # not on an expression
    }
    return int(rows), indexes


def _quoted(name: str) -> str:
    """An SQL identifier, quoted."""
    return '"' + name.replace('"', '""') + '"'


def _columns(database: ResultsDatabase, index: str) -> list[str | None]:
    """The columns of ``index`` in order (None: an expression)."""
    return [row[2] for row in database.rows(f"PRAGMA index_info({_quoted(index)})")]


def _index_stat(database: ResultsDatabase, columns: list[str | None], rows: int) -> str:
    """``sqlite_stat1``'s line of an index on ``columns``: its rows, the rows per value of
    its first column, and 1 for each further column."""
    first = _quoted(str(columns[0]))
    values, value = 0, None
    while values < SEEKS:
        after = "" if value is None else f" WHERE {first} > ?"
        ((value,),) = database.rows(
            f"SELECT MIN({first}) FROM {TABLE}{after}", () if value is None else (value,)
        )
        if value is None:
            break
        values += 1
    if values < SEEKS:
        per_value = -(-rows // max(values, 1))  # rounded up
    else:
        ((sampled, distinct),) = database.rows(
            f"SELECT COUNT(*), COUNT(DISTINCT {first}) FROM "
            f"(SELECT {first} FROM {TABLE} ORDER BY rowid DESC LIMIT {SAMPLE_ROWS})"
        )
        per_value = max(1, round(sampled / max(distinct, 1)))
    return " ".join(str(figure) for figure in (rows, per_value, *[1] * (len(columns) - 1)))
