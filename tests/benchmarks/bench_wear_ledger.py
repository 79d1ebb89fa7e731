"""The wear ledger's cost of one counted run, as a tool's history grows.

Run: ``.venv/bin/python tests/benchmarks/bench_wear_ledger.py [--history 1000 10000 100000]``
(not collected by pytest). For each history length, one tool's ledger is filled
with that many runs, then runs are counted one at a time as the recorder counts
them with a service threshold set: the run written (``add_run``), then the tool's
intensity since service asked, either read from its whole interval
(``WearLedger.tool``, what the recorder asked before) or kept from the rows added
(``WearLedger.since_service``). The two ways alternate, five rounds, medians
printed side by side: milliseconds per counted run and their ratio.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from shared.contract import RunSummary
from shared.wear import (
    CONTRACT_LIMITS,
    WearLedger,
)
from tests.support.factories import summary

T0_NS = 1_700_000_000_000_000_000
S_NS = 1_000_000_000
TOOL = 7
COUNTED = 200  # runs counted per round and way
ROUNDS = 5


def run(run_id: int) -> RunSummary:
    """A 1 s run of the tool, ended ``run_id`` seconds after T0."""
    ended_ns = T0_NS + run_id * S_NS
    return summary(
        run_id,
        tool_id=TOOL,
        events=4,
        process_intensity=1.0e5,
        samples=1000,
        started_ns=ended_ns - S_NS,
        ended_ns=ended_ns,
    )


def fill(path: Path, runs: int) -> None:
    with WearLedger(path) as ledger:
        ledger.record_service(TOOL, "first socket", T0_NS)
        for run_id in range(1, runs + 1):
            ledger.add_run(run(run_id), T0_NS, CONTRACT_LIMITS)


def ms_per_run(ledger: WearLedger, first_id: int, ask: Callable[[int], object]) -> float:
    started = time.perf_counter()
    for run_id in range(first_id, first_id + COUNTED):
        ledger.add_run(run(run_id), T0_NS, CONTRACT_LIMITS)
        ask(TOOL)
    return (time.perf_counter() - started) * 1e3 / COUNTED


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--history", type=int, nargs="+", default=[1_000, 10_000, 100_000])
    args = parser.parse_args()
    print("history runs | whole interval (tool) ms/run | kept (since_service) ms/run | ratio")
    for history in args.history:
        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / "wear.sqlite"
            fill(path, history)
            whole: list[float] = []
            kept: list[float] = []
            next_id = history + 1
            with WearLedger(path) as ledger:
                for _round in range(ROUNDS):
                    whole.append(
                        ms_per_run(ledger, next_id, lambda t: ledger.tool(t, outlook=False))
                    )
                    next_id += COUNTED
                    kept.append(ms_per_run(ledger, next_id, ledger.since_service))
                    next_id += COUNTED
            w, k = statistics.median(whole), statistics.median(kept)
            print(f"{history:>12} | {w:>28.3f} | {k:>27.3f} | {w / k:.1f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
