"""Cost of the Rerun recording: the sink alone, and MCAP + Rerun in the recorder, per sample.

Run: ``.venv/bin/python tests/benchmarks/bench_recorder_rerun.py`` (not collected by pytest).
No zenoh: payloads are classified up front (sink alone) or per sample (recorder),
with a simulated 1 kHz receive clock so flush ticks fall once a second.

CPU is ``time.process_time()``: every thread of the process, so Rerun's
batcher and file-writer threads are counted, not just the caller's.
Stations per core = 1 s of CPU / (CPU per sample x 1000 samples per second).
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from services.recorder.live.recorder import Recorder
from services.recorder.live.run_files import FileLimits
from shared.config import load_station
from shared.contract import (
    Sample,
    StickSlipEvent,
    ToolState,
    encode,
)
from shared.recordings import (
    FileMetadata,
    Received,
    classify,
)
from shared.recordings.rerun import RerunOptions, RerunSink
from tests.support.live_recorder import write_station_file

SAMPLES = 60_000  # one minute at 1 kHz
RATE_HZ = 1000


def run_payloads(t0_ns: int) -> list[tuple[str, bytes]]:
    """(key, payload): ToolState running, samples, an event every 100 samples."""
    out = [("boltwatch/st1/tool", encode(ToolState("st1", 1, 7, 1, "running", t0_ns)))]
    for n in range(SAMPLES):
        t_ns = t0_ns + n * 1_000_000
        sample = Sample("st1", 1, n, t_ns, 100.0 + n * 1e-3, n * 0.01, 5e4 + n)
        out.append(("boltwatch/st1/samples", encode(sample)))
        if n % 100 == 99:
            event = StickSlipEvent(
                "st1", 1, n // 100, t_ns, n / 1e3, 120.0, 100.0, 20.0, 5e4, 500.0, 0.1,
                10.0, 1.0, 2.0, 3.0, 0.5, 0.01 * n,
            )  # fmt: skip
            out.append(("boltwatch/st1/events", encode(event)))
    return out


def bench_sink(tmp: Path, items: list[Received], batch_samples: int) -> None:
    path = tmp / f"sink_{batch_samples}.rrd"
    started_ns = items[0].message.time_ns
    cpu0, wall0 = time.process_time(), time.perf_counter()
    sink = RerunSink(path, "st1", 1, started_ns, RerunOptions(batch_samples=batch_samples))
    for n, item in enumerate(items):
        sink.write(item)
        if n % RATE_HZ == 0:
            sink.flush()  # the recorder's flush tick, once a second of samples
    sink.close()
    cpu, wall = time.process_time() - cpu0, time.perf_counter() - wall0
    print(
        f"sink alone, batches of {batch_samples:4d}: {SAMPLES / wall:9.0f} samples/s wall, "
        f"{cpu / SAMPLES * 1e6:5.1f} µs CPU/sample, "
        f"{path.stat().st_size / SAMPLES:5.1f} bytes/sample .rrd"
    )


def bench_recorder(tmp: Path, payloads: list[tuple[str, bytes]], rerun: bool) -> float:
    loaded = load_station(
        write_station_file(tmp / "station.toml", tmp / f"rec_{rerun}", ["tcp/127.0.0.1:1"])
    )
    limits = FileLimits(1_000_000_000, 1 << 40, 3600 * 1_000_000_000)
    options = RerunOptions() if rerun else None
    recorder = Recorder(loaded.recordings_folder, limits, FileMetadata(loaded), options)
    t0_ns = time.time_ns()
    cpu0, wall0 = time.process_time(), time.perf_counter()
    for n, (key, payload) in enumerate(payloads):
        recorder.write(classify(key, payload, t0_ns + n * 1_000_000))
    write_cpu = time.process_time() - cpu0
    close0 = time.perf_counter()
    closed = recorder.close()
    close_s = time.perf_counter() - close0
    cpu, wall = time.process_time() - cpu0, time.perf_counter() - wall0
    per_sample_us = cpu / SAMPLES * 1e6
    sizes = {path.suffix: path.stat().st_size for path in closed}
    rrd = closed[0].with_suffix(".rrd")
    if rrd.exists():
        sizes[".rrd"] = rrd.stat().st_size
    label = "MCAP + Rerun" if rerun else "MCAP only   "
    print(
        f"recorder, {label}: {per_sample_us:5.1f} µs CPU/sample "
        f"(writing {write_cpu / SAMPLES * 1e6:5.1f}), wall {wall / SAMPLES * 1e6:5.1f} µs/sample, "
        f"close {close_s * 1e3:5.0f} ms; {1000 / per_sample_us:5.1f} stations of 1 kHz per core; "
        + ", ".join(f"{ext} {size / SAMPLES:.1f} B/sample" for ext, size in sizes.items())
    )
    return per_sample_us


def main() -> None:
    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        t0_ns = time.time_ns()
        payloads = run_payloads(t0_ns)
        arrival_ns = t0_ns + SAMPLES * 1_000_000  # after every sample's time: none refused
        items = [classify(key, payload, arrival_ns) for key, payload in payloads]
        for batch in (100, 250, 1000, 2000):
            bench_sink(tmp, items, batch)
        mcap_us = bench_recorder(tmp, payloads, rerun=False)
        both_us = bench_recorder(tmp, payloads, rerun=True)
        print(f"Rerun adds {both_us - mcap_us:.1f} µs CPU per sample to the recorder")


if __name__ == "__main__":
    main()
