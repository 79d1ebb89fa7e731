"""Recorder throughput without zenoh: classify + MCAP write + flush per second of samples.

Run: ``.venv/bin/python tests/benchmarks/bench_recorder_write.py [--repeats N]`` (not
collected by pytest). Writes one minute of 1 kHz samples (a flush per simulated second)
with ``fsync`` on (each flush reaches the disk: what the recorder does) and off (a flush
only reaches the OS), alternating, and prints the medians side by side: wall time per
sample (fsync waits for the disk, not the CPU), recorder CPU per sample, and the cost of
one flush. The budget is 1000 µs per sample. Last, the close of a run file (fsync on):
finished where it was written, and finished then renamed from its writing name with the
folder synced (what the recorder does, so a crash never leaves a broken run file).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from services.recorder.live.recorder import Recorder
from services.recorder.live.run_files import FileLimits
from shared.config import load_station
from shared.contract import (
    Sample,
    ToolState,
    encode,
)
from shared.recordings import (
    FileMetadata,
    classify,
)
from shared.recordings.mcap import McapSink
from tests.support.live_recorder import write_station_file

SAMPLES = 60_000  # one minute at 1 kHz
FLUSHES = SAMPLES // 1000  # the simulated receive clock flushes once a second


@dataclass(frozen=True, slots=True)
class Trial:
    wall_us_per_sample: float
    cpu_us_per_sample: float
    bytes_per_sample: float


def one_trial(folder: Path, payloads: list[bytes], t0: int, fsync: bool) -> Trial:
    loaded = load_station(
        write_station_file(folder / "station.toml", folder / "rec", listen=["tcp/127.0.0.1:1"])
    )
    limits = FileLimits(1_000_000_000, 1 << 40, 3600 * 1_000_000_000, fsync=fsync)
    recorder = Recorder(loaded.recordings_folder, limits, FileMetadata(loaded))
    recorder.write(
        classify("boltwatch/st1/tool", encode(ToolState("st1", 1, 7, 1, "running", t0)), t0)
    )
    wall_start, cpu_start = time.perf_counter(), time.process_time()
    for n, payload in enumerate(payloads):
        # Simulated receive clock: 1 ms apart, so the recorder flushes once a second.
        recorder.write(classify("boltwatch/st1/samples", payload, t0 + n * 1_000_000))
    wall_s, cpu_s = time.perf_counter() - wall_start, time.process_time() - cpu_start
    (path,) = recorder.close()
    assert recorder.write_errors == 0
    return Trial(wall_s / SAMPLES * 1e6, cpu_s / SAMPLES * 1e6, path.stat().st_size / SAMPLES)


def flush_times_ms(folder: Path, payloads: list[bytes], t0: int, fsync: bool) -> list[float]:
    """Wall time of each flush of one second of samples, straight on an McapSink."""
    times: list[float] = []
    sink = McapSink(folder / f"flush-{fsync}.mcap", {}, 1, t0, fsync=fsync)
    with sink:
        for n, payload in enumerate(payloads):
            sink.write(classify("boltwatch/st1/samples", payload, t0 + n * 1_000_000))
            if n % 1000 == 999:
                start = time.perf_counter()
                sink.flush()
                times.append((time.perf_counter() - start) * 1e3)
    return times


CLOSED_FILES = 100  # run files closed per trial, each of 50 samples


def close_times_ms(folder: Path, payloads: list[bytes], t0: int, rename: bool) -> list[float]:
    """Wall time of each run file's close (fsync on), renamed once complete or not."""
    times: list[float] = []
    for n in range(CLOSED_FILES):
        path = folder / f"close-{rename}-{n}.mcap"
        sink = McapSink(path, {}, n, t0, rename_when_complete=rename)
        for k, payload in enumerate(payloads[:50]):
            sink.write(classify("boltwatch/st1/samples", payload, t0 + k * 1_000_000))
        sink.flush()
        start = time.perf_counter()
        sink.close()
        times.append((time.perf_counter() - start) * 1e3)
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=5, help="trials per setting (default 5)")
    parser.add_argument(
        "--folder", type=Path, default=None, help="where to write (default: a temporary folder)"
    )
    args = parser.parse_args()
    t0 = time.time_ns()
    payloads = [
        encode(Sample("st1", 1, n, t0 + n * 1_000_000, 100.0 + n * 1e-3, n * 0.01, 5e4))
        for n in range(SAMPLES)
    ]
    trials: dict[bool, list[Trial]] = {True: [], False: []}
    flushes_ms: dict[bool, list[float]] = {True: [], False: []}
    closes_ms: dict[bool, list[float]] = {True: [], False: []}
    with tempfile.TemporaryDirectory(dir=args.folder) as folder:
        for repeat in range(args.repeats):
            for fsync in (False, True):
                trial_folder = Path(folder) / f"{repeat}-{fsync}"
                trial_folder.mkdir()
                trials[fsync].append(one_trial(trial_folder, payloads, t0, fsync))
                flushes_ms[fsync] += flush_times_ms(trial_folder, payloads, t0, fsync)
            for rename in (False, True):
                closes_ms[rename] += close_times_ms(trial_folder, payloads, t0, rename)
    print(f"{SAMPLES} samples, {FLUSHES} flushes per trial, {args.repeats} trials each, medians:")
    medians = {}
    for fsync in (False, True):
        wall = statistics.median(t.wall_us_per_sample for t in trials[fsync])
        cpu = statistics.median(t.cpu_us_per_sample for t in trials[fsync])
        size = statistics.median(t.bytes_per_sample for t in trials[fsync])
        medians[fsync] = wall
        label = "fsync on " if fsync else "fsync off"
        print(
            f"  {label}: {wall:.2f} µs/sample wall, {cpu:.2f} µs/sample CPU "
            f"(budget 1000 µs), {size:.1f} bytes/sample on disk"
        )
    print(f"  wall time with fsync / without: {medians[True] / medians[False]:.2f}x")
    for fsync in (False, True):
        times = sorted(flushes_ms[fsync])
        print(
            f"  one flush of 1 s of samples, fsync {'on ' if fsync else 'off'}: median "
            f"{statistics.median(times):.2f} ms, p90 {times[int(len(times) * 0.9)]:.2f} ms "
            f"({len(times)} flushes)"
        )
    for rename in (False, True):
        times = sorted(closes_ms[rename])
        label = "renamed from its writing name" if rename else "under its name"
        print(
            f"  close of a run file, {label}: median {statistics.median(times):.2f} ms, "
            f"p90 {times[int(len(times) * 0.9)]:.2f} ms ({len(times)} files)"
        )


if __name__ == "__main__":
    main()
