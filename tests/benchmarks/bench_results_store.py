"""The results store, measured: how fast results go in while recording, how fast a part and a
month are found in 10 million, and the file scan it replaces (not a test).

Run on demand::

    .venv/bin/python tests/benchmarks/bench_results_store.py [--rows 10000000]
        [--steps 1234] [--databases sqlite postgresql] [--folder FOLDER]
        [--postgres-url URL] [--explain] [--readers-only]

1. **Ingest while recording** (goal ≥ 200 results a second): a real recorder
   serving ``--stations`` stations hears their results over zenoh on loopback
   at rising rates (``--rates``, ``--seconds`` each) and stores them
   (``results_ingest.live_ingest``): per step the rate put, the time until the
   last is in the store, the rate sustained and the largest backlog. SQLite
   beside the recordings; PostgreSQL, the tests' server (``fsync`` off), and
   a second one with ``fsync``, ``synchronous_commit`` and ``full_page_writes``
   on (a plant's).
2. **ResultsStore.add alone**, in batches of 1, 10, 100 and 1000 results: the
   store's raw rate, for reference, into the same three stores.
3. **Queries over ``--rows`` synthetic results** (``synthetic_results``: 20
   stations on 2 lines, a year), written into the store's own tables; its
   size on disk and how long writing took. (a) ``ResultsStore.find`` by part
   id for 1000 random parts that exist (goal p99 ≤ 50 ms); (b) a month's
   report: ``read_stored`` of 30 days of the 20 stations, then
   ``program_statistics`` on what it read (goal ≤ 5 s; the median of
   ``--repeats``). ``--explain``: the plan of each statement ``find`` runs
   (SQLite ``EXPLAIN QUERY PLAN``, PostgreSQL ``EXPLAIN (ANALYZE, BUFFERS)``).
   ``--readers-only``: no writer opens the store first (as a recorder's start does) and
   its SQLite statistics are deleted: a store only readers open (an older boltwatch's
   ``results rebuild``, a copy), with the first reader's open timed.
4. **The file scan it replaces**: ``read_results`` over ``--files`` run files
   written by the real recorder (``run_recordings``), per file, extrapolated
   to the month of a 20-station line at a run every 30 s (1 728 000 files).

``--folder`` keeps the SQLite store and the run files there and reuses them
when they hold what is asked (default: a temporary folder, removed);
``--postgres-url`` uses that server's database (filled when empty, reused
when it holds ``--rows``) instead of starting the tests' server.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import random
import resource
import statistics
import sys
import tempfile
import time
from collections.abc import Iterator, Sequence
from datetime import UTC, datetime, timedelta
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from shared.offline.report import ResultFilter, read_results, read_stored
from shared.quality import statistics_of
from shared.results import ResultsDatabase, ResultsQuery, ResultsStore, StoreError, StoreTarget
from tests.benchmarks.results_ingest import add_rates, live_ingest
from tests.benchmarks.run_recordings import record_runs
from tests.benchmarks.synthetic_results import (
    START_NS,
    STATIONS,
    fill_postgres,
    fill_sqlite,
)
from tests.support.postgres_server import PostgresServer, start_postgres_server

#: a plant's PostgreSQL: what the tests' server turns off
FSYNC_ON = {"fsync": "on", "synchronous_commit": "on", "full_page_writes": "on"}
#: the month of a 20-station line at a run every 30 s: its files (one a run) and results
MONTH_RUNS = 20 * 30 * 86_400 // 30
SUBGROUP_SIZE = 5  # report's default
SAMPLES_PER_RUN = 1700  # the paper's program: 1.7 s at 1 kHz
PLAN_LINES = 30  # of a plan printed


def percentile(values: Sequence[float], share: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(share * len(ordered)))]


@contextlib.contextmanager
def postgres(url: str | None, settings: dict[str, str] | None = None) -> Iterator[str]:
    """``url``, or the url of a new tests' server (``settings`` over its own) until the end."""
    if url is not None:
        yield url
        return
    server: PostgresServer = start_postgres_server(settings=settings)
    with server:
        yield server.url


def ingest(args: argparse.Namespace, folder: Path) -> dict[str, Any]:
    """Steps 1 and 2 into SQLite, PostgreSQL (fsync off) and PostgreSQL (fsync on)."""
    figures: dict[str, Any] = {}
    stores: list[tuple[str, dict[str, str] | None]] = [("sqlite", None)]
    if "postgresql" in args.databases:
        stores += [("postgresql, fsync off", None), ("postgresql, fsync on", FSYNC_ON)]
    for name, settings in stores:
        with contextlib.ExitStack() as stack:
            url = None
            if name != "sqlite":
                url = stack.enter_context(postgres(None, settings))
            here = folder / f"ingest-{len(figures)}"
            steps = []
            if "1" in args.steps:
                steps = live_ingest(here / "live", url, args.stations, args.rates, args.seconds)
                for step in steps:
                    print(f"1. ingest, {name}, {args.stations} stations: {step.line()}", flush=True)
            adds = []
            if "2" in args.steps:
                target = (
                    StoreTarget(sqlite_path=here / "add" / "results.sqlite")
                    if url is None
                    else StoreTarget(postgres_url=url)
                )
                adds = add_rates(target, (1, 10, 100, 1000), args.add_results)
                for add in adds:
                    print(f"2. ResultsStore.add, {name}: {add.line()}", flush=True)
            figures[name] = {
                "live": [
                    {
                        "offered_per_s": s.offered_per_s,
                        "put_per_s": round(s.put_per_s),
                        "sustained_per_s": round(s.sustained_per_s),
                        "after_last_put_s": round(s.stored_s - s.put_s, 2),
                        "backlog_max": s.backlog_max,
                        "waiting_max": s.waiting_max,
                    }
                    for s in steps
                ],
                "add_per_s": {a.batch: round(a.results / a.seconds) for a in adds},
            }
    return figures


def store_size_bytes(store: ResultsStore) -> int:
    """The tables with their indexes, on disk."""
    if store.target.sqlite_path is not None:
        return sum(
            path.stat().st_size
            for path in store.target.sqlite_path.parent.glob(store.target.sqlite_path.name + "*")
        )
    ((size,),) = store.database.rows(
        "SELECT pg_total_relation_size('tightenings') + pg_total_relation_size('tightening_steps')"
    )
    return int(size)


def filled(args: argparse.Namespace, target: StoreTarget) -> dict[str, Any]:
    """The store ``target`` holding ``--rows`` synthetic results (made now unless it does)."""
    with contextlib.suppress(StoreError), ResultsStore(target, create=False) as store:
        have = store.count(ResultsQuery())
        if have == args.rows:
            print(f"3. {target.dialect}: reusing {have} rows", flush=True)
            return {"reused": True}
        if have:
            raise SystemExit(f"{target} holds {have} rows, not --rows {args.rows}: empty it")
    started = time.monotonic()
    if target.sqlite_path is not None:
        made = fill_sqlite(target.sqlite_path, args.rows, args.days, args.seed)
    else:
        made = fill_postgres(target.postgres_url or "", args.rows, args.days, args.seed)
    took = time.monotonic() - started
    print(
        f"3. {target.dialect}: {made.tightenings} results ({made.steps} steps) written in "
        f"{took:.0f} s ({made.tightenings / took:.0f} a second)",
        flush=True,
    )
    return {"generation_s": round(took), "steps": made.steps}


def without_statistics(target: StoreTarget) -> None:
    """The SQLite store as one only readers ever opened: no ``sqlite_stat1``."""
    if target.sqlite_path is None:
        return
    with ResultsDatabase(target) as database, database.transaction():
        if database.rows("SELECT name FROM sqlite_master WHERE name = 'sqlite_stat1'"):
            database.execute("DELETE FROM sqlite_stat1")


def random_parts(store: ResultsStore, rows: int, count: int, seed: int) -> list[str]:
    """``count`` distinct part ids that exist: those of random (station, run) rows."""
    rng = random.Random(seed)
    parts: set[str] = set()
    runs = rows // STATIONS
    while len(parts) < count:
        station = f"st{rng.randrange(STATIONS) + 1:02d}"
        found = store.database.rows(
            "SELECT part_id FROM tightenings WHERE station = ? AND run_id = ?",
            (station, rng.randrange(runs) + 1),
        )
        parts.update(row[0] for row in found)
    return sorted(parts)[:count]


@contextlib.contextmanager
def recorded(store: ResultsStore) -> Iterator[list[tuple[str, list[Any]]]]:
    """The first statement of each kind the store runs meanwhile, with its values (to be
    explained after it was measured: some take minutes)."""
    seen: dict[str, tuple[str, list[Any]]] = {}
    statements: list[tuple[str, list[Any]]] = []
    rows = store.database.rows

    def recording(sql: str, parameters: Sequence[Any] = ()) -> list[tuple[Any, ...]]:
        kind = sql.split(" WHERE ", maxsplit=1)[0][:120]
        if kind not in seen:
            seen[kind] = (sql, list(parameters))
            statements.append(seen[kind])
        return rows(sql, parameters)

    setattr(store.database, "rows", recording)  # noqa: B010 (an instance's, for a moment)
    try:
        yield statements
    finally:
        delattr(store.database, "rows")


def explain(store: ResultsStore, statements: list[tuple[str, list[Any]]], what: str) -> None:
    for sql, parameters in statements:
        if store.database.dialect == "sqlite":
            plan = [row[3] for row in store.database.rows("EXPLAIN QUERY PLAN " + sql, parameters)]
        else:
            plan = [
                row[0]
                for row in store.database.rows("EXPLAIN (ANALYZE, BUFFERS) " + sql, parameters)
            ]
        print(f"   plan, {what}: {_cut(sql)}")
        for line in plan[:PLAN_LINES]:
            print(f"      {_cut(line)}")
        if len(plan) > PLAN_LINES:
            print(f"      ... {len(plan) - PLAN_LINES} lines more")


def _cut(text: str, chars: int = 200) -> str:
    return text if len(text) <= chars else text[: chars - 3] + "..."


def queries(args: argparse.Namespace, target: StoreTarget) -> dict[str, Any]:
    """Step 3 on ``target``."""
    figures = filled(args, target)
    if args.readers_only:  # a store no writer opens (an older rebuild's, a copy)
        without_statistics(target)
        started = time.perf_counter()
        ResultsStore(target, create=False).close()  # the first reader: its statistics
        figures["first_reader_open_s"] = round(time.perf_counter() - started, 3)
        print(f"3. {target.dialect}: the first reader's open: {figures['first_reader_open_s']} s")
    else:
        with ResultsStore(target):  # opened by its writer, as a recorder starts: statistics
            pass
    with ResultsStore(target, create=False) as store:
        size = store_size_bytes(store)
        figures["bytes_per_million_rows"] = round(size / args.rows * 1e6)
        parts = random_parts(store, args.rows, args.lookups, args.seed)
        times: list[float] = []
        found = 0
        part_statements: list[tuple[str, list[Any]]] = []
        for part in parts:  # the first one's statements recorded (a dict look-up each)
            with recorded(store) if not times else contextlib.nullcontext() as seen:
                started = time.perf_counter()
                found += len(store.find(ResultsQuery(part_id=part)))
                times.append(time.perf_counter() - started)
            part_statements += seen or []
        figures["part_ms"] = {
            "p50": round(percentile(times, 0.5) * 1e3, 2),
            "p99": round(percentile(times, 0.99) * 1e3, 2),
            "max": round(max(times) * 1e3, 2),
        }
        print(
            f"3. {target.dialect}, {args.rows} rows, {size / 1e9:.2f} GB "
            f"({size / args.rows * 1e6 / 1e6:.0f} MB per million): a part by id, "
            f"{len(parts)} parts ({found / len(parts):.1f} tightenings each): p50 "
            f"{figures['part_ms']['p50']} ms, p99 {figures['part_ms']['p99']} ms, max "
            f"{figures['part_ms']['max']} ms (goal p99 ≤ 50 ms)",
            flush=True,
        )
        since = datetime.fromtimestamp(START_NS / 1e9, UTC) + timedelta(days=args.month_day)
        rule = ResultFilter(
            stations=[(f"st{n:02d}", Path()) for n in range(1, STATIONS + 1)],
            since=since,
            until=since + timedelta(days=30),
        )
        reads, stats, totals, results = [], [], [], 0
        month_statements: list[tuple[str, list[Any]]] = []
        rss_before_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        for repeat in range(args.repeats):
            started = time.perf_counter()
            with recorded(store) if repeat == 0 else contextlib.nullcontext() as seen:
                read = read_stored(store, rule)
            month_statements += seen or []
            read_s = time.perf_counter() - started
            for columns in read.programs:
                statistics_of(columns, SUBGROUP_SIZE)
            total_s = time.perf_counter() - started
            reads.append(read_s)
            stats.append(total_s - read_s)
            totals.append(total_s)
            results = read.results
            del read
        grown_mb = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - rss_before_kb) / 1024
        read_s, stats_s, total_s = (statistics.median(v) for v in (reads, stats, totals))
        figures["month"] = {
            "results": results,
            "read_stored_s": round(read_s, 2),
            "program_statistics_s": round(stats_s, 2),
            "total_s": round(total_s, 2),
            "per_result_us": round(total_s / results * 1e6, 2),
            "statistics_per_result_us": round(stats_s / results * 1e6, 2),
            "peak_rss_grown_mb": round(grown_mb),
        }
        print(
            f"3. {target.dialect}, a month of {STATIONS} stations ({results} results): "
            f"read_stored {read_s:.2f} s + program_statistics {stats_s:.2f} s = "
            f"{total_s:.2f} s (median of {args.repeats}; goal ≤ 5 s); at a run every 30 s "
            f"({MONTH_RUNS} results) scaled per result: {total_s / results * MONTH_RUNS:.1f} s; "
            f"the process's peak memory grew by {grown_mb:.0f} MB",
            flush=True,
        )
        if args.explain:
            explain(store, part_statements, "a part")
            explain(store, month_statements, "a month")
    return figures


def file_scan(args: argparse.Namespace, folder: Path, stats_us: float | None) -> dict[str, Any]:
    """Step 4."""
    recordings = folder / "runs" / "recordings"
    files = sorted(recordings.rglob("*.mcap")) if recordings.exists() else []
    if len(files) != args.files:
        started = time.monotonic()
        recordings = record_runs(folder / "runs", args.files, SAMPLES_PER_RUN, args.seed)
        files = sorted(recordings.rglob("*.mcap"))
        print(f"4. {len(files)} run files recorded in {time.monotonic() - started:.0f} s")
    size = sum(path.stat().st_size for path in files) / len(files)
    rule = ResultFilter(stations=[("st1", recordings)])
    took = []
    for _ in range(args.repeats):
        started = time.perf_counter()
        read = read_results(rule)
        took.append(time.perf_counter() - started)
        assert read.results == args.files, read.results
    per_file_s = statistics.median(took) / len(files)
    month_s = per_file_s * MONTH_RUNS
    with_stats = month_s + (stats_us or 0.0) * 1e-6 * MONTH_RUNS
    print(
        f"4. read_results over {len(files)} run files ({size / 1e3:.0f} kB each, "
        f"{SAMPLES_PER_RUN} samples a run): {statistics.median(took):.1f} s, "
        f"{per_file_s * 1e3:.2f} ms a file (median of {args.repeats}); extrapolated to a "
        f"month of a 20-station line at a run every 30 s ({MONTH_RUNS} files): "
        f"{month_s / 3600:.1f} h"
        + (f", with program_statistics {with_stats / 3600:.1f} h" if stats_us else ""),
        flush=True,
    )
    return {
        "files": len(files),
        "file_kb": round(size / 1e3),
        "per_file_ms": round(per_file_s * 1e3, 2),
        "month_extrapolated_h": round(month_s / 3600, 1),
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", default="1234", help="which steps (default 1234)")
    parser.add_argument(
        "--databases", nargs="+", default=["sqlite", "postgresql"], choices=["sqlite", "postgresql"]
    )
    parser.add_argument("--stations", type=int, default=10, help="stations of step 1 (10)")
    parser.add_argument(
        "--rates", type=float, nargs="+", default=[50, 200, 1000, 5000],
        help="results a second, all stations together, step by step (50 200 1000 5000)",
    )  # fmt: skip
    parser.add_argument("--seconds", type=float, default=10.0, help="of each rate (10)")
    parser.add_argument("--add-results", type=int, default=2000, help="per batch size (2000)")
    parser.add_argument("--rows", type=int, default=10_000_000, help="synthetic results")
    parser.add_argument("--days", type=float, default=365.0, help="they span (365)")
    parser.add_argument("--month-day", type=int, default=181, help="the month's first day")
    parser.add_argument("--lookups", type=int, default=1000, help="random parts (1000)")
    parser.add_argument("--repeats", type=int, default=3, help="of the month and the scan")
    parser.add_argument("--files", type=int, default=2000, help="run files scanned (2000)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--folder", type=Path, default=None, help="keep and reuse files here")
    parser.add_argument("--postgres-url", default=None, help="a server's database for step 3")
    parser.add_argument("--explain", action="store_true", help="print each query's plan")
    parser.add_argument(
        "--readers-only",
        action="store_true",
        help="step 3 on a store no writer opens (its SQLite statistics deleted): the first "
        "reader's open and what the readers after it find",
    )
    args = parser.parse_args()
    figures: dict[str, Any] = {"rows": args.rows}
    with contextlib.ExitStack() as stack:
        folder = args.folder or Path(stack.enter_context(tempfile.TemporaryDirectory()))
        folder.mkdir(parents=True, exist_ok=True)
        if "1" in args.steps or "2" in args.steps:
            scratch = Path(stack.enter_context(tempfile.TemporaryDirectory(dir=folder)))
            figures["ingest"] = ingest(args, scratch)
        stats_us = None
        if "3" in args.steps:
            for database in args.databases:
                if database == "sqlite":
                    target = StoreTarget(sqlite_path=folder / "synthetic" / "results.sqlite")
                    figures["sqlite"] = queries(args, target)
                else:
                    with postgres(args.postgres_url) as url:
                        figures["postgresql"] = queries(args, StoreTarget(postgres_url=url))
                stats_us = figures[database]["month"]["statistics_per_result_us"]
        if "4" in args.steps:
            figures["files"] = file_scan(args, folder, stats_us)
    print(json.dumps(figures))
    return 0


if __name__ == "__main__":
    sys.exit(main())
