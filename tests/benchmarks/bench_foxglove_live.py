"""The recorder's cost per sample with the live Foxglove view: off, no client, a client.

Run: ``.venv/bin/python tests/benchmarks/bench_foxglove_live.py [--repeats N]`` (not
collected by pytest). Files 20 s of one station's 1 kHz samples as the recorder's worker
does (each sample classified, written to MCAP with fsync off, and handed to
:class:`FoxgloveLive`), three ways, alternating: no Foxglove server, a server with no
client, a server with a real WebSocket client (:mod:`tests.support.foxglove_client`) subscribed
to the samples. Prints the medians of the worker thread's CPU per sample (the server's
own threads and the client are not the recorder's cost, and share the two cores) and how
many samples the client received.
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

from services.recorder.foxglove_live.foxglove_server import FoxgloveLive
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
from tests.support.foxglove_client import FoxgloveClient
from tests.support.live_recorder import free_port, write_station_file

SAMPLES = 20_000
KEY = "boltwatch/st1/samples"


def one_trial(folder: Path, payloads: list[bytes], t0: int, mode: str) -> tuple[float, int]:
    loaded = load_station(
        write_station_file(folder / "station.toml", folder / "rec", listen=["tcp/127.0.0.1:1"])
    )
    limits = FileLimits(1_000_000_000, 1 << 40, 3600 * 1_000_000_000, fsync=False)
    recorder = Recorder(loaded.recordings_folder, limits, FileMetadata(loaded))
    recorder.write(
        classify("boltwatch/st1/tool", encode(ToolState("st1", 1, 7, 1, "running", t0)), t0)
    )
    live = FoxgloveLive(["st1"], "127.0.0.1", free_port()) if mode != "off" else None
    client = None
    if live is not None and mode == "client":
        client = FoxgloveClient(live.url, [KEY])
        assert client.subscribed.wait(10) and client.error is None, client.error
        time.sleep(0.2)  # the subscription reaches the server
    cpu_start = time.thread_time()
    for n, payload in enumerate(payloads):
        received = classify(KEY, payload, t0 + n * 1_000_000)
        recorder.write(received)
        if live is not None:
            live.log(received)
    cpu_s = time.thread_time() - cpu_start
    recorder.close()
    got = 0
    if client is not None:
        time.sleep(0.5)
        got = len(client.received(KEY))
        client.close()
    if live is not None:
        live.close()
    return cpu_s / len(payloads) * 1e6, got


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    t0 = time.time_ns()
    payloads = [
        encode(Sample("st1", 1, n, t0 + n * 1_000_000, 100.0 + n % 50, n * 0.01, 1000.0 + n))
        for n in range(SAMPLES)
    ]
    results: dict[str, list[float]] = {"off": [], "no client": [], "client": []}
    received: list[int] = []
    for _ in range(args.repeats):
        for mode, label in (("off", "off"), ("server", "no client"), ("client", "client")):
            with tempfile.TemporaryDirectory() as tmp:
                cpu_us, got = one_trial(Path(tmp), payloads, t0, mode)
            results[label].append(cpu_us)
            if mode == "client":
                received.append(got)
    for label, values in results.items():
        print(
            f"Foxglove {label:>9}: recorder CPU {statistics.median(values):6.2f} us/sample "
            f"(runs: {', '.join(f'{v:.2f}' for v in values)})"
        )
    print(f"client received {received} of {SAMPLES} samples per run")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
