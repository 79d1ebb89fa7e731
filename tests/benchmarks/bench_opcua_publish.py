"""The OPC UA server under load: results a second it publishes to 5 subscribed clients that
ask each result's trace, and the line recorder's figures with the server beside it and
without it (not a test).

Run on demand::

    .venv/bin/python tests/benchmarks/bench_opcua_publish.py [--stations 10]
        [--rates 10 50 200] [--seconds 10] [--clients 5] [--rounds 2] [--round-seconds 20]
        [--samples 1700] [--folder FOLDER]

Real processes on loopback: a router, ``serve recorder`` (MCAP only, the line
server's configuration; its results store SQLite beside the recordings) and ``serve
opcua`` (Basic256Sha256 sign and encrypt, client certificates signed by a CA it
trusts, each client logged in as a user of its users file) serving ``--stations``
stations, and ``--clients`` node-opcua clients (``opcua_publish_client.js``, a
process each: subscribed to every station's result-ready events, each result's trace
asked by ``GetResultById`` one call at a time, oldest first).

Before: each station's runs (``--samples`` samples at 1 kHz) recorded by the real
recorder (``run_recordings``) and put into the results store by ``boltwatch
results rebuild``, so each result served has its real trace
(``opcua_publish_line``: the processes, the recordings, the results put). Once
the clients have subscribed, results are put one a second until 3 in a row reach
every client within 0.5 s (the first ones after subscribing take seconds: up to
20 s with a 20 ms publishing interval), not counted.

1. **Publishing**: per rate of ``--rates`` (results a second, all stations
   together, round robin), ``--seconds`` of those results put on
   ``boltwatch/<st>/results`` (as the recorder stores them). Per step: the
   results whose event every client received and the rate sustained (first put
   to the last receipt), the event latency p50/p99 (put -> a client's receipt,
   every client's, CLOCK_MONOTONIC on both sides), the traces answered (all
   clients) and a call's latency p50/p99, the server's CPU (share of one core,
   first put to the step's end). A step waits up to ``--drain-s`` for the last
   events, then for the traces until twice ``--seconds`` after the first put
   (the traces a second: those answered over that time); the traces not asked
   by then are dropped (the clients' queues).
2. **The recorder with and without the server**: ``--rounds`` pairs A/B, A
   without the server, B with it and its clients: the line load of
   ``bench_line.py``'s generator (a ``SampleBatch`` of 50 samples every 50 ms
   per station, 1 s runs 0.2 s apart) for ``--round-seconds``, and results
   at ``--line-rate`` a second (all stations: a run each every 1.2 s). Per
   round: the recorder's CPU µs a sample and its lag p50/p99
   (``RecorderStats``), samples missing, the server's CPU and the clients'
   figures (B).

The load average at each step is printed: the machine is shared. ``--profile
FILE``: part 1's server runs under cProfile (``opcua_profiled_server.py``: its
asyncio loop and its GetResultById calls), and the heaviest functions are
printed after part 1.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import pstats
import re
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

import zenoh

from shared.config import derive_stations
from shared.contract import channels
from shared.runtime import zenoh_config
from tests.benchmarks.bench_line import RecorderHeard, cpu_s, wait_alive
from tests.benchmarks.opcua_publish_clients import (
    figures_json,
    percentile,
    step_figures,
    wait_answered,
    wait_delivered,
)
from tests.benchmarks.opcua_publish_line import WARM_UP_S, Line, Results, recorded, stored_results
from tests.support.station_files import free_tcp_port, write_station

LINE_RUN_S = 1.2  # bench_line's generator: a 1 s run, 0.2 s apart
PROFILE_LINES = 30


def load() -> str:
    return "load " + " ".join(f"{figure:.1f}" for figure in os.getloadavg())


def publishing(args: argparse.Namespace, line: Line, results: Results) -> list[dict[str, Any]]:
    """Part 1: the steps of ``--rates`` with the server and its clients."""
    assert line.server is not None
    intervals = {client.publishing_interval_ms for client in line.clients}
    print(f"1. {len(line.clients)} clients subscribed (publishing interval {intervals} ms)")
    steps = []
    for rate in args.rates:
        cpu0, started = cpu_s(line.server), time.monotonic()
        put_ns = results.put(rate, args.seconds)
        ids = list(put_ns)
        delivered = wait_delivered(line.clients, ids, args.drain_s)
        wait_answered(line.clients, ids, started + 2 * args.seconds)
        took_s = time.monotonic() - started
        server_cpu = (cpu_s(line.server) - cpu0) / took_s
        for client in line.clients:
            client.skip()
        figures = step_figures(line.clients, put_ns)
        print(
            f"1. {rate:g}/s for {args.seconds:g} s, {len(line.stations)} stations: "
            f"{figures.line(took_s)}; server CPU {server_cpu:.0%} of a core over {took_s:.1f} s"
            f"{'' if delivered else ' (events still missing at the drain limit)'}; {load()}",
            flush=True,
        )
        steps.append(
            {
                "offered_per_s": rate,
                **figures_json(figures),
                "server_cpu_core_share": round(server_cpu, 2),
                "step_s": round(took_s, 1),
                "load": os.getloadavg()[0],
            }
        )
    return steps


def generator_samples(log: Path) -> int:
    found = re.findall(r"generator: (\d+) samples", log.read_text())
    return int(found[-1]) if found else 0


def line_round(
    args: argparse.Namespace, line: Line, results: Results, heard: RecorderHeard, name: str
) -> dict[str, Any]:
    """One round of part 2: the generator's line load and results at ``--line-rate``."""
    log = line.folder / f"generator-{name}.log"
    with heard.lock:
        missing_before = sum(heard.missing.values())
        heard.lag_p50_ms.clear()
        heard.lag_max_ms.clear()
    recorder0 = cpu_s(line.recorder)
    server0 = cpu_s(line.server) if line.server else 0.0
    with log.open("wb") as out:
        generator = subprocess.Popen(
            [
                *(sys.executable, str(REPO / "tests/benchmarks/bench_line.py"), "--generate"),
                *(line.endpoint, "--seconds", str(args.round_seconds), *line.files),
            ],
            cwd=REPO,
            stdout=out,
            stderr=subprocess.STDOUT,
        )
    started = time.monotonic()
    time.sleep(1.0)  # its own wait for the router to learn the subscribers
    with heard.lock:
        heard.listening = True
    put_ns = results.put(args.line_rate, args.round_seconds - 1.0)
    generator.wait(timeout=args.round_seconds + 60)
    time.sleep(3.0)  # the last batches filed, the last BusStats counted and reported
    with heard.lock:
        heard.listening = False
        lag_p50 = statistics.median(heard.lag_p50_ms) if heard.lag_p50_ms else math.nan
        lag_p99 = percentile(heard.lag_max_ms, 0.99)
        missing = sum(heard.missing.values()) - missing_before
    took_s = time.monotonic() - started
    samples = generator_samples(log)
    figures: dict[str, Any] = {
        "round": name,
        "recorder_cpu_us_per_sample": round((cpu_s(line.recorder) - recorder0) / samples * 1e6, 2)
        if samples
        else None,
        "recorder_lag_p50_ms": round(lag_p50, 1),
        "recorder_lag_p99_ms": round(lag_p99, 1),
        "samples": samples,
        "samples_missing": missing,
        "load": os.getloadavg()[0],
    }
    if line.server is not None:
        figures["server_cpu_core_share"] = round((cpu_s(line.server) - server0) / took_s, 2)
        wait_delivered(line.clients, list(put_ns), args.drain_s)
        figures.update(figures_json(step_figures(line.clients, put_ns)))
        for client in line.clients:
            client.skip()
    print(f"2. {name}: {json.dumps(figures)}; {load()}", flush=True)
    return figures


def beside(
    args: argparse.Namespace, line: Line, session: zenoh.Session, results: Results
) -> list[dict[str, Any]]:
    """Part 2: A (no server) and B (the server and its clients), ``--rounds`` times."""
    heard = RecorderHeard()
    subscriber = session.declare_subscriber(channels.RECORDER.key("*"), heard.on_stats)
    rounds = []
    try:
        for n in range(1, args.rounds + 1):
            line.stop_server()
            rounds.append(line_round(args, line, results, heard, f"A{n} without the server"))
            line.start_server(session, results)
            rounds.append(line_round(args, line, results, heard, f"B{n} with the server"))
    finally:
        subscriber.undeclare()
    for kind in ("A", "B"):
        mine = [r for r in rounds if r["round"].startswith(kind)]
        us = [r["recorder_cpu_us_per_sample"] for r in mine if r["recorder_cpu_us_per_sample"]]
        print(
            f"2. {kind}: recorder CPU a sample, median {statistics.median(us):.2f} µs "
            f"({', '.join(f'{u:.2f}' for u in us)}); lag p99 "
            f"{', '.join(str(r['recorder_lag_p99_ms']) for r in mine)} ms",
            flush=True,
        )
    return rounds


def runs_needed(args: argparse.Namespace) -> int:
    """Runs a station for every result put (and the server's newest at start, kept back)."""
    total = sum(max(1, round(rate * args.seconds)) for rate in args.rates)
    total += 2 * args.rounds * max(1, round(args.line_rate * args.round_seconds))
    total += (args.rounds + 1) * WARM_UP_S  # at most, one a second
    return math.ceil(total / args.stations) + 10


@contextlib.contextmanager
def folder_of(args: argparse.Namespace) -> Iterator[Path]:
    if args.folder is not None:
        args.folder.mkdir(parents=True, exist_ok=True)
        yield args.folder
        return
    with tempfile.TemporaryDirectory(prefix="bench-opcua-") as scratch:
        yield Path(scratch)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--stations", type=int, default=10)
    parser.add_argument(
        "--rates", type=float, nargs="*", default=[10, 50, 200],
        help="results a second of part 1, all stations together (10 50 200; none: no part 1)",
    )  # fmt: skip
    parser.add_argument("--seconds", type=float, default=10.0, help="of each rate (10)")
    parser.add_argument("--drain-s", type=float, default=30.0, help="a step's last events (30)")
    parser.add_argument("--clients", type=int, default=5)
    parser.add_argument("--publishing-interval-ms", type=float, default=100.0, help="(100)")
    parser.add_argument("--rounds", type=int, default=2, help="A/B pairs of part 2 (0: none)")
    parser.add_argument("--round-seconds", type=float, default=20.0, help="a round's load (20)")
    parser.add_argument("--line-rate", type=float, default=None, help="part 2's results a second")
    parser.add_argument("--samples", type=int, default=1700, help="a run's (1.7 s at 1 kHz)")
    parser.add_argument("--folder", type=Path, default=None, help="keep and reuse files here")
    parser.add_argument(
        "--profile", type=Path, default=None, metavar="FILE",
        help="part 1's server under cProfile (opcua_profiled_server.py), its pstats into FILE",
    )  # fmt: skip
    args = parser.parse_args(argv)
    if args.line_rate is None:
        args.line_rate = args.stations / LINE_RUN_S
    figures: dict[str, Any] = {"load_at_start": os.getloadavg()}
    with folder_of(args) as folder:
        port = free_tcp_port()
        base = write_station(folder, zenoh_port=port)
        files = derive_stations(base, args.stations, folder / "stations")
        runs = runs_needed(args)
        recorded(args, folder, files, runs)
        line = Line(args, folder, files, f"tcp/127.0.0.1:{port}")
        try:
            line.start()
            stored = stored_results(files, runs * args.stations)
            with zenoh.open(zenoh_config("client", [line.endpoint])) as session:
                results = Results(session, stored)
                wait_alive(session, {(s, "recorder") for s in line.stations}, [], folder)
                if args.rates:
                    line.start_server(session, results, args.profile)
                    figures["publishing"] = publishing(args, line, results)
                    if args.profile is not None:
                        line.stop_server()
                        stats = pstats.Stats(str(args.profile))
                        stats.sort_stats("tottime").print_stats(PROFILE_LINES)
                        stats.sort_stats("cumulative").print_stats(PROFILE_LINES)
                if args.rounds:
                    figures["beside"] = beside(args, line, session, results)
                results.close()
        finally:
            line.close()
    figures["load_at_end"] = os.getloadavg()
    print(json.dumps(figures))
    return 0


if __name__ == "__main__":
    sys.exit(main())
