"""What GetResultIdListFiltered costs the OPC UA server (not a test): the ResultIds of a
filter's results from a SQLite results store of many, as the method gives them (its output
arguments, before encoding).

Run on demand::

    .venv/bin/python tests/benchmarks/bench_opcua_result_ids.py [--results 100000]
        [--repeats 5]

A store of ``--results`` tightenings of st1 (and as many of st2), one a second, every
tenth NOK; per filter the median of ``--repeats``: every result (MaxResults 0: the
answer's most, 10 000, and the error that more match), the NOKs, the last hour, and
the newest 100.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from services.opcua.result_requests import result_ids
from shared.results import ResultsQuery, ResultsStore, StoreTarget, store_target, stored_result
from tests.support import factories

SECOND_NS = 1_000_000_000


def fill(folder: Path, count: int) -> StoreTarget:
    target = store_target(folder, None)
    with ResultsStore(target) as store:
        for start in range(0, count, 5000):
            batch = []
            for run in range(start + 1, min(start + 5000, count) + 1):
                for station in ("st1", "st2"):
                    verdict = "NOK" if run % 10 == 0 else "OK"
                    result = factories.result(
                        run, station=station, time_ns=factories.T0 + run * SECOND_NS, result=verdict
                    )
                    batch.append(stored_result(result, "", None, "h", 1))
            store.add(batch)
    return target


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--results", type=int, default=100_000, help="tightenings a station")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    every = ResultsQuery(stations=["st1"], limit=None)
    last_ns = factories.T0 + args.results * SECOND_NS
    filters = {
        "every result (MaxResults 0)": (every, 0),
        "NOK (ResultEvaluation 2)": (replace(every, verdict="NOK"), 0),
        "the last hour (CreationTime >=)": (replace(every, since_ns=last_ns - 3600 * SECOND_NS), 0),
        "the newest 100 (MaxResults 100)": (every, 100),
    }
    with tempfile.TemporaryDirectory() as scratch:
        target = fill(Path(scratch), args.results)
        for name, (query, most) in filters.items():
            times_s = []
            for _ in range(args.repeats):
                started = time.perf_counter()
                _handle, ids, error = result_ids(target, "st1", query, most)
                times_s.append(time.perf_counter() - started)
            print(
                f"{name}: {len(ids.Value)} ids, Error {error.Value}, "
                f"median {statistics.median(times_s) * 1000:.0f} ms"
            )


if __name__ == "__main__":
    main()
