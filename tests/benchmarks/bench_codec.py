"""CPU per call of the codec: encode and decode of a Sample and of a StickSlipEvent.

Run on demand (not collected by pytest), in turn on two checkouts for a side by side::

    git worktree add /tmp/before <commit>
    (cd /tmp/before && PYTHONPATH=. /path/to/.venv/bin/python tests/benchmarks/bench_codec.py)
    .venv/bin/python tests/benchmarks/bench_codec.py

``time.process_time`` over ``--calls`` calls, the median of ``--repeats``, in µs.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from shared.contract import (
    Prediction,
    Sample,
    StickSlipEvent,
    codec,
)

SAMPLE = Sample("st1", 17, 1234, 1_700_000_000_000_000_000, 12.5, 345.25, 31000.0, 1.234)
EVENT = StickSlipEvent(
    "st1", 1, 2, 3, 0.5, 10.0, 9.0, 1.0, 30000.0, 200.0, 0.1, 10.0, 0.5, 0.4, 0.3, 2.0, 4.0,
    [Prediction(1, 0.6, 11.0, 30100.0), Prediction(2, 0.7, 12.0, 30200.0)],
)  # fmt: skip


def median_us(call: Callable[[], object], calls: int, repeats: int) -> float:
    runs = []
    for _ in range(repeats):
        started = time.process_time()
        for _ in range(calls):
            call()
        runs.append((time.process_time() - started) / calls * 1e6)
    return statistics.median(runs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=50_000)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    sample_payload, event_payload = codec.encode(SAMPLE), codec.encode(EVENT)
    decode_sample = codec.decoder(Sample)
    assert decode_sample(sample_payload) == SAMPLE
    assert codec.decode(StickSlipEvent, event_payload) == EVENT
    cases: dict[str, Callable[[], object]] = {
        "Sample decode": lambda: decode_sample(sample_payload),
        "Sample encode": lambda: codec.encode(SAMPLE),
        "StickSlipEvent decode": lambda: codec.decode(StickSlipEvent, event_payload),
        "StickSlipEvent encode": lambda: codec.encode(EVENT),
    }
    for name, call in cases.items():
        print(f"{name:24s} {median_us(call, args.calls, args.repeats):7.2f} µs")


if __name__ == "__main__":
    main()
