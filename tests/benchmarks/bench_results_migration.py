"""The results store's migration from version 1 to this boltwatch's (2: the plant model, 3:
the part's source), measured on a large store of version 1 (not a test).

Run on demand::

    .venv/bin/python tests/benchmarks/bench_results_migration.py [--rows 1000000]
        [--databases sqlite postgresql] [--postgres-url URL]

For each database: a store of version 1 (the tables and indexes of
``MIGRATIONS[:1]``) filled with ``--rows`` synthetic results
(``synthetic_results``: 20 stations on 2 lines, a year), then the time
``migrate`` takes to bring it to this version (two ``ALTER TABLE ... ADD COLUMN``
with a default and the ``plant`` index, then a nullable ``part_source``, each
version one transaction under the store's lock: the recorder's start, or a
reader's, waits for it), the store's size
before and after, and that every row is there with ``plant`` ``''``.
PostgreSQL is the tests' server (``fsync`` off) unless ``--postgres-url``
names an empty database.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from shared.results import SCHEMA_VERSION, ResultsDatabase, StoreTarget, migrate, version_of
from tests.benchmarks.synthetic_results import fill_postgres, fill_sqlite
from tests.support.postgres_server import start_postgres_server


@contextlib.contextmanager
def _postgres(url: str | None) -> Iterator[str]:
    if url is not None:
        yield url
        return
    with start_postgres_server() as server:
        yield server.url


def _size_bytes(database: ResultsDatabase) -> int:
    if database.target.sqlite_path is not None:
        path = database.target.sqlite_path
        return sum(p.stat().st_size for p in path.parent.glob(path.name + "*"))
    with database.transaction():
        ((size,),) = database.rows("SELECT pg_database_size(current_database())")
    return int(size)


def measure(target: StoreTarget, rows: int) -> str:
    """Fill ``target`` at version 1, migrate it, check it; one line of figures."""
    started_s = time.monotonic()
    if target.sqlite_path is not None:
        fill_sqlite(target.sqlite_path, rows, 365.0, 7, version=1)
    else:
        fill_postgres(target.postgres_url or "", rows, 365.0, 7, version=1)
    filled_s = time.monotonic() - started_s
    with ResultsDatabase(target) as database:
        assert version_of(database) == 1
        before = _size_bytes(database)
        started_s = time.monotonic()
        assert migrate(database) == 1
        took_s = time.monotonic() - started_s
        after = _size_bytes(database)
        with database.transaction():
            ((count, unplaced),) = database.rows(
                "SELECT COUNT(*), SUM(CASE WHEN plant = '' THEN 1 ELSE 0 END) FROM tightenings"
            )
    assert (count, unplaced) == (rows, rows), (count, unplaced)
    return (
        f"{target.dialect}: {rows} rows of version 1 (filled in {filled_s:.0f} s): migrated to "
        f"version {SCHEMA_VERSION} in {took_s:.2f} s; {before / 1e6:.0f} MB before, "
        f"{after / 1e6:.0f} MB after"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rows", type=int, default=1_000_000)
    parser.add_argument(
        "--databases", nargs="+", choices=("sqlite", "postgresql"), default=["sqlite", "postgresql"]
    )
    parser.add_argument("--postgres-url", default=None)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        if "sqlite" in args.databases:
            target = StoreTarget(sqlite_path=Path(folder) / "results.sqlite")
            print(measure(target, args.rows), flush=True)
        if "postgresql" in args.databases:
            with _postgres(args.postgres_url) as url:
                print(measure(StoreTarget(postgres_url=url), args.rows), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
