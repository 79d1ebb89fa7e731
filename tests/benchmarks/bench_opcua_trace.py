"""What a result's trace costs the OPC UA server (not a test): its run's samples read from an
MCAP recording written by the real sink, and turned into the fields of IJT's
``JoiningTraceDataType`` (what ``GetResultById`` does per call, before encoding).

Run on demand::

    .venv/bin/python tests/benchmarks/bench_opcua_trace.py [--samples 3000] [--runs 1 20]
        [--repeats 5]

Per file of ``--runs`` runs of ``--samples`` samples each (the recorder starts a
file per run: 1 is the usual case), the median of ``--repeats``: the time to read
one run's samples from it (:func:`services.opcua.result_trace.recorded_samples`)
and to make its trace (:func:`~services.opcua.result_trace.trace_values`).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from services.opcua.result_trace import recorded_samples, trace_values
from shared.contract import encode
from shared.recordings import classify
from shared.recordings.mcap import McapSink
from tests.support import factories


def recording(folder: Path, runs: int, samples: int) -> Path:
    with McapSink(folder / f"runs{runs}.mcap", {}, 1, factories.T0) as sink:
        for run in range(1, runs + 1):
            for n in range(samples):
                sample = factories.sample(run, n, torque_nm=10.0 + n, angle_deg=0.1 * n)
                sink.write(classify("boltwatch/st1/samples", encode(sample), sample.time_ns))
    return sink.path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--samples", type=int, default=3000, help="samples a run (3 s at 1 kHz)")
    parser.add_argument("--runs", type=int, nargs="+", default=[1, 20], help="runs a file")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        for runs in args.runs:
            path = recording(Path(scratch), runs, args.samples)
            read_s, trace_s = [], []
            for _ in range(args.repeats):
                started = time.perf_counter()
                samples = recorded_samples(path, "st1", runs)  # the file's last run
                read_s.append(time.perf_counter() - started)
                started = time.perf_counter()
                trace_values(f"st1/{runs}", samples)
                trace_s.append(time.perf_counter() - started)
            assert len(samples) == args.samples
            print(
                f"{runs} runs, {runs * args.samples} samples, "
                f"{path.stat().st_size / 1e6:.1f} MB: read {statistics.median(read_s):.3f} s, "
                f"trace {statistics.median(trace_s) * 1000:.1f} ms"
            )


if __name__ == "__main__":
    main()
