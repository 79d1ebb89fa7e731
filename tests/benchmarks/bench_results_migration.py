"""The results store's migrations, measured on a large store of the version before (not a
test).

Run on demand::

    .venv/bin/python tests/benchmarks/bench_results_migration.py [--rows 1000000]
        [--to-version 4] [--absurd 100] [--databases sqlite postgresql] [--postgres-url URL]

For each database: a store of the version before ``--to-version`` (the tables and indexes
of ``MIGRATIONS[:version]``) filled with ``--rows`` synthetic results
(``synthetic_results``: 20 stations on 2 lines, a year), then the time ``migrate`` takes
to bring it to ``--to-version`` (one transaction under the store's lock: the recorder's
start, or a reader's, waits for it), the store's size before and after, and that every
row is where it belongs:

- version 2 (the plant model): two ``ALTER TABLE ... ADD COLUMN`` with a default and the
  ``plant`` index; every row kept with ``plant`` ``''``;
- version 3 (the part's source): a nullable ``part_source``, no row rewritten;
- version 4 (one rule for what a result is): ``refused_tightenings`` made and the rows
  whose figures cannot be a measurement moved there (two reads of the table); the store
  of version 3 holds ``--absurd`` such rows besides (a final torque of 1e308 Nm, as an
  older ``results rebuild`` stored them), and every other row stays.

PostgreSQL is the tests' server (``fsync`` off) unless ``--postgres-url`` names an empty
database.
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

from shared.results import (
    MIGRATIONS,
    SCHEMA_VERSION,
    ResultsDatabase,
    StoreTarget,
    migrate,
    version_of,
)
from tests.benchmarks.synthetic_results import fill_postgres, fill_sqlite
from tests.support.old_results_store import columns_of
from tests.support.postgres_server import start_postgres_server

#: a torque no tightening has: what an older ``results rebuild`` stored as a result
ABSURD_NM = 1e308
#: the version that keeps tightenings whose figures cannot be a measurement aside
REFUSED_VERSION = 4


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


def _add_absurd(database: ResultsDatabase, absurd: int, version: int) -> None:
    """``absurd`` copies of existing rows of a store of ``version``, each of another station
    (``absurd-<station>``) and a torque of 1e308."""
    changed = {"station": "'absurd-' || station", "torque_nm": repr(ABSURD_NM)}
    kept = columns_of(version)
    columns = ", ".join(changed.get(column, column) for column in kept)
    with database.transaction():
        database.execute(
            f"INSERT INTO tightenings ({', '.join(kept)}) "
            f"SELECT {columns} FROM tightenings LIMIT {absurd}"
        )


def measure(target: StoreTarget, rows: int, to_version: int, absurd: int) -> str:
    """Fill ``target`` at the version before ``to_version``, migrate it, check it; one line
    of figures."""
    before_version = to_version - 1
    started_s = time.monotonic()
    if target.sqlite_path is not None:
        fill_sqlite(target.sqlite_path, rows, 365.0, 7, version=before_version)
    else:
        fill_postgres(target.postgres_url or "", rows, 365.0, 7, version=before_version)
    filled_s = time.monotonic() - started_s
    with ResultsDatabase(target) as database:
        assert version_of(database) == before_version
        if to_version == REFUSED_VERSION:
            _add_absurd(database, absurd, before_version)
        before = _size_bytes(database)
        started_s = time.monotonic()
        assert migrate(database, MIGRATIONS[:to_version]) == before_version
        took_s = time.monotonic() - started_s
        after = _size_bytes(database)
        with database.transaction():
            ((count, unplaced),) = database.rows(
                "SELECT COUNT(*), SUM(CASE WHEN plant = '' THEN 1 ELSE 0 END) FROM tightenings"
            )
            refused = 0
            if to_version == REFUSED_VERSION:
                ((refused,),) = database.rows("SELECT COUNT(*) FROM refused_tightenings")
    if to_version == 2:
        assert (count, unplaced) == (rows, rows), (count, unplaced)
    elif to_version == REFUSED_VERSION:
        assert (count, refused) == (rows, absurd), (count, refused)
    else:
        assert count == rows, count
    aside = f", {refused} moved aside" if to_version == REFUSED_VERSION else ""
    return (
        f"{target.dialect}: {rows} rows of version {before_version} (filled in {filled_s:.0f} "
        f"s): migrated to version {to_version} in {took_s:.2f} s{aside}; "
        f"{before / 1e6:.0f} MB before, {after / 1e6:.0f} MB after"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rows", type=int, default=1_000_000)
    parser.add_argument(
        "--to-version", type=int, choices=range(2, SCHEMA_VERSION + 1), default=SCHEMA_VERSION
    )
    parser.add_argument(
        "--absurd", type=int, default=100, help=f"rows to move (version {REFUSED_VERSION})"
    )
    parser.add_argument(
        "--databases", nargs="+", choices=("sqlite", "postgresql"), default=["sqlite", "postgresql"]
    )
    parser.add_argument("--postgres-url", default=None)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        if "sqlite" in args.databases:
            target = StoreTarget(sqlite_path=Path(folder) / "results.sqlite")
            print(measure(target, args.rows, args.to_version, args.absurd), flush=True)
        if "postgresql" in args.databases:
            with _postgres(args.postgres_url) as url:
                target = StoreTarget(postgres_url=url)
                print(measure(target, args.rows, args.to_version, args.absurd), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
