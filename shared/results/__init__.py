"""The results store: every tightening result, findable in a second (by part, station,
plant, line, program, tool, time), in SQLite beside the recordings or a plant's PostgreSQL.

- :mod:`.results_database` (one connection, SQLite or PostgreSQL, the same SQL;
  :func:`store_target`: where a station file's store is)
- :mod:`.results_schema` (the tables, their version, the migrations)
- :mod:`.stored_result` (a result as a row, and back)
- :mod:`.results_store` (add idempotently, find, a query's keys only, what was read
  of which recording)
- :mod:`.refused_results` (the tightenings kept aside: figures that cannot be a
  measurement, never a result to a reader; named in the report's words)
- :mod:`.sqlite_statistics` (SQLite's planner statistics, written by the store's writer,
  and by a reader that finds none)
- :mod:`.results_query` (which tightenings a question asks for)
- :mod:`.program_columns` (a report's columns per program, in one scan)

The recorder writes it (``services/recorder/results_watch.py``); ``boltwatch
results`` reads it.
"""

from shared.results.program_columns import StoredColumns, program_columns
from shared.results.results_database import (
    SQLITE_FILE,
    ResultsDatabase,
    StoreError,
    StoreTarget,
    postgres_target,
    station_store,
    store_target,
    without_password,
)
from shared.results.results_query import DEFAULT_LIMIT, ResultsQuery, time_ns_of
from shared.results.results_schema import MIGRATIONS, SCHEMA_VERSION, migrate, version_of
from shared.results.results_store import ResultsStore
from shared.results.stored_result import StoredResult, stored_result

__all__ = [
    "DEFAULT_LIMIT",
    "MIGRATIONS",
    "SCHEMA_VERSION",
    "SQLITE_FILE",
    "ResultsDatabase",
    "ResultsQuery",
    "ResultsStore",
    "StoreError",
    "StoreTarget",
    "StoredColumns",
    "StoredResult",
    "migrate",
    "postgres_target",
    "program_columns",
    "station_store",
    "store_target",
    "stored_result",
    "time_ns_of",
    "version_of",
    "without_password",
]
