"""Memory of the recorder over many runs: does anything grow per run?

Run: ``.venv/bin/python tests/benchmarks/bench_recorder_memory.py [--runs 120]``
(not collected by pytest). No zenoh: the recorder gets classified payloads on
a simulated 1 kHz clock, 1700 samples a run (the paper's program), with and
without the Rerun ``.rrd`` files, and prints the resident memory every 20
runs. Before pooling Rerun streams (``shared/recordings/rerun/rerun_streams.py``)
this showed +1.5 MiB per run with Rerun on.
"""

from __future__ import annotations

import argparse
import gc
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))

SAMPLES_PER_RUN = 1700


def rss_mib() -> float:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return float("nan")


def one_recorder(runs: int, rerun: bool) -> None:
    from services.recorder.live.recorder import Recorder
    from services.recorder.live.run_files import FileLimits
    from shared.config import load_station
    from shared.contract import Sample, ToolState, encode
    from shared.recordings import FileMetadata, classify
    from shared.recordings.rerun import RerunOptions
    from tests.support.live_recorder import write_station_file

    tmp = Path(tempfile.mkdtemp(prefix="boltwatch-memory-"))
    station_file = write_station_file(tmp / "station.toml", tmp / "rec", ["tcp/127.0.0.1:1"])
    loaded = load_station(station_file)
    limits = FileLimits(1_000_000_000, 1 << 40, 3600 * 1_000_000_000)
    options = RerunOptions() if rerun else None
    recorder = Recorder(loaded.recordings_folder, limits, FileMetadata(loaded), options)
    t_ns = time.time_ns()
    label = "MCAP + Rerun" if rerun else "MCAP only   "
    first = None
    for run_id in range(1, runs + 1):
        running = ToolState("st1", run_id, 7, 1, "running", t_ns)
        recorder.write(classify("boltwatch/st1/tool", encode(running), t_ns))
        for n in range(SAMPLES_PER_RUN):
            t_ns += 1_000_000
            sample = Sample("st1", run_id, n, t_ns, 100.0 + n * 0.01, n * 0.01, 5e4 + n)
            recorder.write(classify("boltwatch/st1/samples", encode(sample), t_ns))
            if n % 500 == 0:
                recorder.tick(t_ns)
        done = ToolState("st1", run_id, 7, 1, "done", t_ns)
        recorder.write(classify("boltwatch/st1/tool", encode(done), t_ns))
        if run_id % 20 == 0:
            gc.collect()
            now = rss_mib()
            first = first if first is not None else (run_id, now)
            print(f"{label} run {run_id:4d}: {now:6.1f} MiB", flush=True)
    recorder.close()
    assert first is not None
    per_run = (rss_mib() - first[1]) / max(runs - first[0], 1)
    print(f"{label} growth after run {first[0]}: {per_run * 1024:+.1f} KiB per run", flush=True)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=120)
    parser.add_argument("--mode", choices=("both", "rerun", "mcap"), default="both")
    args = parser.parse_args()
    if args.mode != "both":
        one_recorder(args.runs, rerun=args.mode == "rerun")
        return 0
    for mode in ("mcap", "rerun"):  # each in its own process: memory is per process
        command = [sys.executable, __file__, "--runs", str(args.runs), "--mode", mode]
        subprocess.run(command, check=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
