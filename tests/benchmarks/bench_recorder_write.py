"""Recorder throughput without zenoh: classify + MCAP write + flush per second of samples.

Run: ``.venv/bin/python tests/benchmarks/bench_recorder_write.py`` (not collected by pytest).
Prints microseconds of recorder CPU per 1 kHz sample; the budget is 1000 µs.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from services.recorder.file_metadata import FileMetadata
from services.recorder.incoming import classify
from services.recorder.recorder import Recorder
from services.recorder.run_files import FileLimits
from services.recorder.testing import write_station_file
from shared.codec import encode
from shared.config import load_station
from shared.messages import Sample, ToolState

SAMPLES = 60_000  # one minute at 1 kHz


def main() -> None:
    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        loaded = load_station(
            write_station_file(tmp / "station.toml", tmp / "rec", listen=["tcp/127.0.0.1:1"])
        )
        limits = FileLimits(1_000_000_000, 1 << 40, 3600 * 1_000_000_000)
        recorder = Recorder(loaded.recordings_folder, limits, FileMetadata(loaded))
        t0 = time.time_ns()
        payloads = [
            encode(Sample("st1", 1, n, t0 + n * 1_000_000, 100.0 + n * 1e-3, n * 0.01, 5e4))
            for n in range(SAMPLES)
        ]
        recorder.write(
            classify("boltwatch/st1/tool", encode(ToolState("st1", 1, 7, 1, "running", t0)), t0)
        )
        start = time.perf_counter()
        for n, payload in enumerate(payloads):
            # Simulated receive clock: 1 ms apart, so the recorder flushes once a second.
            recorder.write(classify("boltwatch/st1/samples", payload, t0 + n * 1_000_000))
        elapsed = time.perf_counter() - start
        (path,) = recorder.close()
        size = path.stat().st_size
    per_sample_us = elapsed / SAMPLES * 1e6
    print(
        f"{SAMPLES} samples: {per_sample_us:.1f} µs/sample recorder CPU (budget 1000 µs), "
        f"{size / SAMPLES:.1f} bytes/sample on disk (zstd, 1 s chunks)"
    )


if __name__ == "__main__":
    main()
