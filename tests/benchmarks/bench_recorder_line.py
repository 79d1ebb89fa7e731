"""The line recorder's filing work for N stations, in-process: what ``bench_line.py`` loads
the recorder with, without the zenoh receive.

Run on demand (not collected by pytest)::

    .venv/bin/python tests/benchmarks/bench_recorder_line.py --stations 50 --seconds 6
    .venv/bin/python tests/benchmarks/bench_recorder_line.py --no-rerun --profile 25

A real :class:`~services.recorder.service.RecorderService` (its zenoh session
peer-only, listening on nothing) is handed, every simulated 5 ms, what N edge
stations publish toward the line in that time (``bench_line.py``'s generator:
a ``SampleBatch`` every 50 ms with the events, one every 25 ms, and their
intensities found in it, 1 s runs 0.2 s apart, tool states, a decision and a
summary per run, bus and
predictor statistics every second), stamped with a simulated clock, and ticks
as its worker does (flush every half flush interval). No sleeping: the figure
is CPU per sample (``time.process_time``: every thread of the process, Rerun's
included) and how many simulated seconds one CPU second files.
``--profile N`` prints the N heaviest functions (cProfile, cumulative).
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

import zenoh

from services.recorder.service import RecorderService
from shared.config import derive_stations, load_station
from shared.contract import channels
from shared.runtime import (
    ServiceSkeleton,
    zenoh_config,
)
from tests.benchmarks.bench_line import (
    BATCH_SAMPLES,
    RUN_PAUSE_TICKS,
    RUN_SAMPLES,
    StationPayloads,
    events_in,
    run_rows,
)
from tests.support.station_files import write_station

TAKE_MS = 5  # the service's TAKE_INTERVAL_S


def line_load(
    stations: list[StationPayloads], seconds: float, t0_ns: int
) -> Iterator[tuple[int, list[tuple[str, bytes]]]]:
    """Per simulated 5 ms: (now_ns, [(key, payload), ...]) of every station."""
    keys = [{c.topic: c.key(station.station) for c in channels.CHANNELS} for station in stations]
    run_id = 1_000_000
    now_ns = t0_ns
    end_ns = t0_ns + round(seconds * 1e9)
    pending: list[tuple[str, bytes]] = []
    while now_ns < end_ns:
        run_id += 1
        for n in range(RUN_SAMPLES + RUN_PAUSE_TICKS):
            now_ns += 1_000_000
            for station, key in zip(stations, keys, strict=True):
                if n == 0:
                    pending.append(
                        (key[channels.TOOL.topic], station.tool(run_id, "running", now_ns))
                    )
                if n < RUN_SAMPLES and n % BATCH_SAMPLES == BATCH_SAMPLES - 1:
                    batch = station.batch(n // BATCH_SAMPLES, run_id, now_ns, events_in(n))
                    pending.append((key[channels.SAMPLE_BATCHES.topic], batch))
                if n == RUN_SAMPLES:
                    pending.append((key[channels.TOOL.topic], station.tool(run_id, "done", now_ns)))
                    pending.append((key[channels.DECISION.topic], station.decision % run_id))
                    pending.append((key[channels.RUNS.topic], station.summary % run_id))
            if n % TAKE_MS == TAKE_MS - 1:
                yield now_ns, pending
                pending = []


def bench(count: int, seconds: float, rerun: bool, profile: int) -> None:
    rows = run_rows()
    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        paths = derive_stations(write_station(tmp, zenoh_mode="peer"), count, tmp / "stations")
        loaded = [load_station(path) for path in paths]
        t0_ns = time.time_ns()
        stations = [
            StationPayloads(station.station_id, station.config.station.tool_id, rows, t0_ns)
            for station in loaded
        ]
        load = list(line_load(stations, seconds, t0_ns))  # encoded before the clock starts
        samples = sum(p.count(b'"torque_nm"') for _now, batch in load for _k, p in batch)
        with ServiceSkeleton("recorder", zenoh.open(zenoh_config("peer", []))) as skeleton:
            service = RecorderService(loaded, skeleton, rerun_files=rerun)
            tick_ns = round(service._tick_s * 1e9)
            profiler = cProfile.Profile() if profile else None
            cpu0, wall0 = time.process_time(), time.perf_counter()
            if profiler:
                profiler.enable()
            next_tick_ns = t0_ns
            for now_ns, batch in load:
                service._file([(key, payload, now_ns, None) for key, payload in batch])
                if now_ns >= next_tick_ns:
                    service.recorder.tick(now_ns)
                    if service.wear is not None:
                        service.wear.tick(now_ns)
                    next_tick_ns = now_ns + tick_ns
            service.recorder.close()
            if profiler:
                profiler.disable()
            cpu, wall = time.process_time() - cpu0, time.perf_counter() - wall0
            if service.wear is not None:
                service.wear.close()
        print(
            f"N={count} {'MCAP + Rerun' if rerun else 'MCAP only'}: {samples} samples, "
            f"{cpu / samples * 1e6:.2f} µs CPU per sample, wall {wall / samples * 1e6:.2f} µs, "
            f"{seconds / cpu:.2f} simulated s per CPU s"
        )
        if profiler:
            pstats.Stats(profiler).sort_stats("cumulative").print_stats(profile)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--stations", type=int, default=50)
    parser.add_argument("--seconds", type=float, default=6.0, help="simulated seconds")
    parser.add_argument("--no-rerun", action="store_true", help="MCAP only")
    parser.add_argument("--profile", type=int, default=0, metavar="N")
    args = parser.parse_args(argv)
    bench(args.stations, args.seconds, not args.no_rerun, args.profile)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
