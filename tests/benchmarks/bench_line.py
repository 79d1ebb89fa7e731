"""A line on one predictor and one recorder: how many 1 kHz stations, at what stop latency.

Run on demand (not collected by pytest)::

    .venv/bin/python tests/benchmarks/bench_line.py --stations 1 10 25 50 [--runs 10]

Per N: one router, ONE ``serve predictor`` and ONE ``serve recorder``
process serving N station files (derived with ``shared.config.derive_stations``,
as ``boltwatch up --stations N`` does). Station st1 is real: its rig and
acquisition run on a udp_multicast bus and the stop path is measured as in
``bench_stop_path.py`` (CAN receive time of the deciding sample in the
acquisition -> StopCommand heard on the CAN bus, kernel timestamps). The
other N-1 stations are a load generator (a separate process, stated: the
2-core machine cannot also run N-1 rigs and acquisitions) publishing
synthetic 1 kHz ``Sample`` streams (the predictor tests' stick-slip
staircase, 1 s runs, ToolState running/done around each) straight on zenoh.

"Keeps up" is read from the line's own outputs: the predictor's RunSummary
of every synthetic run must count all its samples, and its lag (summary
received minus the run's ``done``) stays small; the recorder's RecorderStats
lag (receive minus acquisition time of samples) stays small. The recorder
runs with ``--no-rerun`` (MCAP only) unless ``--rerun``.
"""

from __future__ import annotations

import argparse
import os
import re
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import zenoh

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from services.cli.station_supervisor import stop_process  # noqa: E402
from shared import channels, keys  # noqa: E402
from shared.can_database import StationDatabase  # noqa: E402
from shared.codec import decode, encode  # noqa: E402
from shared.config import derive_stations, load_station  # noqa: E402
from shared.messages import RecorderStats, RunSummary, ToolState  # noqa: E402
from shared.zenoh_session import zenoh_config  # noqa: E402
from tests.benchmarks.line_station_runs import (  # noqa: E402
    SHORT_PROGRAM,
    Heard,
    figures,
    tighten,
)
from tests.system.can_injector import StopListener  # noqa: E402
from tests.system.station_files import free_tcp_port, serve, write_station  # noqa: E402
from tests.unit.predictor.synthetic import staircase  # noqa: E402

REAL_STATION = "st1"
START_TIMEOUT_S = 90.0
RUN_TIMEOUT_S = 20.0
SYNTHETIC_PROGRAM = 1
GENERATOR_PAUSE_S = 0.2  # between synthetic runs


# -- the load generator (a child process: python bench_line.py --generate ...) ---------------


def generate(endpoint: str, station_ids: list[str], seconds: float) -> int:
    """Publish 1 kHz synthetic runs for ``station_ids`` for ``seconds`` or until SIGTERM
    (the current run is finished first, so every run the predictor sees is complete)."""
    stopped = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stopped.set())
    trace = staircase(torque_noise_nm=0.2, force_noise_n=30.0, duration_s=1.0)
    rows = [(tq, a, f) for _t, tq, f, a in trace.rows()]
    published = behind_ticks = 0
    with zenoh.open(zenoh_config("client", [endpoint])) as session:
        # BLOCK as the acquisition's publishers: a line that cannot keep up slows the
        # generator (ticks behind schedule) instead of losing samples in the router
        cc = zenoh.CongestionControl.BLOCK
        samples = {
            s: session.declare_publisher(channels.SAMPLES.key(s), congestion_control=cc)
            for s in station_ids
        }
        tools = {
            s: session.declare_publisher(channels.TOOL.key(s), congestion_control=cc)
            for s in station_ids
        }
        time.sleep(1.0)  # let the router learn the subscribers
        end = time.monotonic() + seconds
        run_id = int(time.time()) * 1000
        while time.monotonic() < end and not stopped.is_set():
            run_id += 1
            start_ns = time.time_ns()
            for station_id in station_ids:
                tools[station_id].put(
                    encode(ToolState(station_id, run_id, 1, SYNTHETIC_PROGRAM, "running", start_ns))
                )
            next_tick = time.perf_counter()
            for sequence, (torque, angle, force) in enumerate(rows):
                now_ns = time.time_ns()
                for station_id in station_ids:
                    samples[station_id].put(
                        f'{{"station":"{station_id}","run_id":{run_id},"sequence":{sequence},'
                        f'"time_ns":{now_ns},"torque_nm":{torque},"angle_deg":{angle},'
                        f'"force_n":{force}}}'
                    )
                published += len(station_ids)
                next_tick += 1e-3
                delay = next_tick - time.perf_counter()
                if delay > 0:
                    time.sleep(delay)
                else:
                    behind_ticks += 1
            done_ns = time.time_ns()
            for station_id in station_ids:
                tools[station_id].put(
                    encode(ToolState(station_id, run_id, 1, SYNTHETIC_PROGRAM, "done", done_ns))
                )
            time.sleep(GENERATOR_PAUSE_S)
    print(f"generator: {published} samples, {behind_ticks} ticks behind schedule", flush=True)
    return 0


# -- the benchmark --------------------------------------------------------------------------


@dataclass
class LineHeard:
    """What the benchmark hears from the synthetic stations: summaries and recorder stats."""

    summary_lag_ms: list[float] = field(default_factory=list)
    incomplete_runs: int = 0
    runs: int = 0
    recorder_lag_p50_ms: list[float] = field(default_factory=list)
    recorder_lag_max_ms: list[float] = field(default_factory=list)
    lock: threading.Lock = field(default_factory=threading.Lock)
    expected_samples: int = 0

    def on_summary(self, sample: zenoh.Sample) -> None:
        summary = decode(RunSummary, sample.payload.to_bytes())
        if summary.station == REAL_STATION:
            return
        with self.lock:
            self.runs += 1
            self.summary_lag_ms.append((time.time_ns() - summary.ended_ns) / 1e6)
            if summary.samples != self.expected_samples:
                self.incomplete_runs += 1

    def on_recorder(self, sample: zenoh.Sample) -> None:
        stats = decode(RecorderStats, sample.payload.to_bytes())
        with self.lock:
            if stats.lag_p50_ms is not None:
                self.recorder_lag_p50_ms.append(stats.lag_p50_ms)
            if stats.lag_max_ms is not None:
                self.recorder_lag_max_ms.append(stats.lag_max_ms)


def wait_alive(
    session: zenoh.Session,
    expected: set[tuple[str, str]],
    processes: list[subprocess.Popen[bytes]],
    folder: Path,
) -> None:
    deadline = time.monotonic() + START_TIMEOUT_S
    missing = set(expected)
    while missing:
        dead = [p.args for p in processes if p.poll() is not None]
        if dead:
            raise SystemExit(f"a service exited at start-up: {dead} (logs in {folder})")
        for reply in session.liveliness().get(keys.health_key("*", "*")):
            if reply.ok is not None:
                station_id, tail = keys.split_key(str(reply.ok.key_expr))
                missing.discard((station_id, tail.rsplit("/", 1)[-1]))
        if time.monotonic() > deadline:
            raise SystemExit(
                f"not alive after {START_TIMEOUT_S:.0f} s: {sorted(missing)[:5]} ({folder})"
            )
        time.sleep(0.2)


def cpu_s(process: subprocess.Popen[bytes]) -> float:
    """User + system CPU seconds of a running process (Linux /proc)."""
    fields = Path(f"/proc/{process.pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def percentiles(values: list[float]) -> str:
    if not values:
        return "-"
    p50, p99 = np.percentile(values, [50, 99])
    return f"p50 {p50:.2f} ms, p99 {p99:.2f} ms, max {max(values):.2f} ms (n={len(values)})"


def bench(stations: int, runs: int, rerun: bool, folder: Path) -> dict[str, object]:
    port = free_tcp_port()
    base = write_station(folder, zenoh_port=port, replacements=SHORT_PROGRAM)
    paths = derive_stations(base, stations, folder / "stations")
    real = load_station(paths[0])
    endpoint = f"tcp/127.0.0.1:{port}"
    processes: list[subprocess.Popen[bytes]] = []
    heard = Heard()
    line = LineHeard(expected_samples=len(staircase(duration_s=1.0).rows()))
    synthetic = [p.stem for p in paths[1:]]
    files = [str(p) for p in paths]
    try:
        processes.append(serve(["router", "--listen", endpoint], folder / "router.log"))
        recorder_args = ["recorder", "--config", *files] + ([] if rerun else ["--no-rerun"])
        processes.append(serve(recorder_args, folder / "recorder.log"))
        processes.append(serve(["predictor", "--config", *files], folder / "predictor.log"))
        processes.append(serve(["acquisition", "--config", str(paths[0])], folder / "acq.log"))
        with (
            zenoh.open(zenoh_config("client", [endpoint])) as session,
            StopListener(real.config.can, StationDatabase(real.dbc_path)) as listener,
        ):
            subscribers = [
                session.declare_subscriber(keys.station_key(REAL_STATION, "*"), heard.on_sample),
                session.declare_subscriber(channels.RUNS.key("*"), line.on_summary),
                session.declare_subscriber(channels.RECORDER.key("*"), line.on_recorder),
            ]
            expected = {
                (s, svc) for s in [REAL_STATION, *synthetic] for svc in ("recorder", "predictor")
            }
            wait_alive(session, expected | {(REAL_STATION, "acquisition")}, processes, folder)
            generator = None
            line_processes = {"predictor": processes[2], "recorder": processes[1]}
            cpu_before = {name: cpu_s(p) for name, p in line_processes.items()}
            if synthetic:
                with (folder / "generator.log").open("wb") as out:
                    generator = subprocess.Popen(
                        [
                            sys.executable,
                            __file__,
                            "--generate",
                            endpoint,
                            "--seconds",
                            str(runs * 20.0),
                            *synthetic,
                        ],
                        cwd=REPO,
                        stdout=out,
                        stderr=subprocess.STDOUT,
                    )
                processes.append(generator)
                time.sleep(2.0)  # the load is on before the measured runs
            rig_args = ["rig", "--config", str(paths[0]), "--runs", str(runs), "--program", "1"]
            log = folder / "rig.log"
            _, elapsed_s = tighten(rig_args, log, runs, heard, processes, RUN_TIMEOUT_S)
            if generator is not None:
                stop_process(generator, grace_s=10.0)
                time.sleep(1.5)  # the last summaries and recorder stats
            cpu_used = {name: cpu_s(p) - cpu_before[name] for name, p in line_processes.items()}
            for subscriber in subscribers:
                subscriber.undeclare()
            stops = listener.heard
    finally:
        for process in reversed(processes):
            stop_process(process, grace_s=10.0)
    with heard.lock:
        rows, notes = figures(heard, stops)
    stop_ms = [r.stop_path_ms for r in rows]
    generator_note = (folder / "generator.log").read_text().strip() if synthetic else "-"
    published = re.search(r"generator: (\d+) samples", generator_note)
    load_samples = int(published.group(1)) if published else 0
    cpu_per_sample: dict[str, float | None] = {}
    for name, used in cpu_used.items():
        us = used / load_samples * 1e6 if load_samples else None
        cpu_per_sample[f"{name}_cpu_us_per_sample"] = round(us, 1) if us else None
        # one core's second over one station's 1000 samples a second
        cpu_per_sample[f"{name}_stations_per_core"] = round(1e3 / us) if us else None
    with line.lock:
        result: dict[str, object] = {
            "stations": stations,
            "stop_path": percentiles(stop_ms),
            "stop_p50_ms": float(np.percentile(stop_ms, 50)) if stop_ms else None,
            "stop_p99_ms": float(np.percentile(stop_ms, 99)) if stop_ms else None,
            "measured_runs": f"{len(rows)} of {runs} ({elapsed_s:.0f} s)",
            "synthetic_runs": line.runs,
            "incomplete_synthetic_runs": line.incomplete_runs,
            "predictor_summary_lag": percentiles(line.summary_lag_ms),
            "recorder_lag_p50_median_ms": (
                statistics.median(line.recorder_lag_p50_ms) if line.recorder_lag_p50_ms else None
            ),
            "recorder_lag_max_ms": max(line.recorder_lag_max_ms, default=None),
            "generator": generator_note,
            **cpu_per_sample,
            "notes": notes,
        }
    return result


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--stations", type=int, nargs="+", default=[1, 10, 25, 50])
    parser.add_argument("--runs", type=int, default=10, help="measured runs of st1 per N")
    parser.add_argument("--rerun", action="store_true", help="recorder writes .rrd too")
    parser.add_argument("--keep", type=Path, default=None, help="keep files and logs here")
    parser.add_argument("--generate", default=None, help=argparse.SUPPRESS)
    parser.add_argument("--seconds", type=float, default=0.0, help=argparse.SUPPRESS)
    parser.add_argument("ids", nargs="*", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.generate:
        return generate(args.generate, args.ids, args.seconds)
    for count in args.stations:
        with tempfile.TemporaryDirectory(prefix=f"bench-line-{count}-") as tmp:
            folder = args.keep / f"n{count}" if args.keep else Path(tmp)
            folder.mkdir(parents=True, exist_ok=True)
            result = bench(count, args.runs, args.rerun, folder)
        print(f"N={count}:")
        for key, value in result.items():
            print(f"  {key}: {value}")
        sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
