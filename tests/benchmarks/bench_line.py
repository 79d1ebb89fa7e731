"""A line server for N stations: router + recorder (MCAP and Rerun) against N edge stations.

Run on demand (not collected by pytest)::

    .venv/bin/python tests/benchmarks/bench_line.py --stations 50 100 [--runs 20]

Per N: one router and ONE ``serve recorder`` (MCAP and Rerun ``.rrd``;
``--no-rerun``: MCAP only) serving N + 1 station files (derived as ``boltwatch
up --stations`` derives them). Station st1 is real, with its stop path: its rig
and its acquisition with the edge predictor (placement edge) on a
udp_multicast CAN bus; the stop path is measured as in ``bench_stop_path.py``
(the deciding sample's CAN receive time -> the StopCommand heard on the bus).
The N other stations are one generator process publishing exactly what an edge
station publishes toward the line, at its rates, pre-encoded so the generator
stays cheap: a ``SampleBatch`` of 50 samples every 50 ms (1 s runs, 0.2 s
apart) with the stick-slip events (one every 25 ms) and their intensities
found in it, ``ToolState`` running/done around each run, a decision and a
summary per run, ``BusStats`` (with
its count of published samples: the recorder's loss count) and
``PredictorStats`` once a second. ``--per-sample`` publishes each sample as its
own message instead (the wire before batches; with ``--repo`` a checkout of
an older commit runs the line and st1, for a side-by-side comparison).

Printed per N: recorder CPU µs per sample (all its CPU over the load, per
sample it recorded) and stations per recorder core, recorder lag p50 (median
of the per-second p50s of ``RecorderStats``) and p99 (of the per-second
maxima: an upper bound), samples missing (``RecorderStats.missing_samples``,
end to end), and st1's stop path p50/p90/p99. Exit status 1 when a sample is
missing or a goal is missed: recorder <= 10 µs per sample; at N = 50 lag p99
<= 1 s and the stop path p90 <= 2 ms (docs/benchmarks.md).
"""

from __future__ import annotations

import argparse
import dataclasses
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

from services.cli.station_supervisor import stop_process
from shared.config import LoadedStation, derive_stations, load_station
from shared.contract import (
    BusStats,
    RecorderStats,
    StationDatabase,
    channels,
    decode,
    encode,
    keys,
)
from shared.runtime import declare_channel, zenoh_config
from tests.benchmarks.line_station_runs import (
    SHORT_PROGRAM,
    TOPICS,
    figures,
    summaries_of,
    tighten,
)
from tests.support.can_injector import StopListener
from tests.support.fuzz.payloads import template
from tests.support.listener import Listener
from tests.support.station_files import free_tcp_port, serve, write_station
from tests.support.synthetic_runs import staircase

REAL_STATION = "st1"
START_TIMEOUT_S = 120.0
RUN_SAMPLES = 1000  # 1 s runs at 1 kHz
BATCH_SAMPLES = 50  # every 50 ms (shared.runtime.sample_batching.BATCH_PERIOD_S)
RUN_PAUSE_TICKS = 200  # 0.2 s between runs
EVENT_EVERY_TICKS = 25
RUN_MARK = 987_654_321  # stands for the run id in pre-encoded messages
GOAL_US_PER_SAMPLE = 10.0
GOAL_LAG_P99_MS = 1000.0
GOAL_STOP_P90_MS = 2.0
#: what an edge station publishes toward the line (and ``samples``, with --per-sample)
STATION_CHANNELS = tuple(
    channel for channel in channels.CHANNELS if channel.publisher in ("acquisition", "predictor")
)
#: the real station on the edge (the default placement), the short program
EDGE_PROGRAM = {k: v for k, v in SHORT_PROGRAM.items() if k != "[predictor]\n"}


# -- the generator (a child process: python bench_line.py --generate ...) --------------------


def run_templated(message: object) -> str:
    """The JSON of ``message`` (whose run id is RUN_MARK) with ``%d`` for the run id."""
    return encode(message).decode().replace("%", "%%").replace(str(RUN_MARK), "%d")


def run_rows() -> list[tuple[float, float, float]]:
    """(torque, angle, force) of every sample of a synthetic run: a stick-slip staircase."""
    trace = staircase(torque_noise_nm=0.2, force_noise_n=30.0, duration_s=1.0)
    return [(tq, a, f) for _t, tq, f, a in trace.rows()][:RUN_SAMPLES]


def sample_texts(station: str, rows: list[tuple[float, float, float]]) -> list[str]:
    """Each sample of a run as JSON with ``%d`` for its run id, then its time."""
    return [
        f'{{"station":"{station}","run_id":%d,"sequence":{n},"time_ns":%d,"torque_nm":{tq!r},'
        f'"angle_deg":{angle!r},"force_n":{force!r},"time_s":{n / 1e3!r}}}'
        for n, (tq, angle, force) in enumerate(rows)
    ]


class StationPayloads:
    """What one synthetic edge station publishes, pre-encoded: ``%d`` stands for the run
    id (and, in a batch, its time and each sample's run id and time)."""

    def __init__(
        self, station: str, tool_id: int, rows: list[tuple[float, float, float]], now_ns: int
    ) -> None:
        self.station = station
        self.tool_id = tool_id
        texts = sample_texts(station, rows)
        self.samples = texts
        self.batches = [
            f'{{"station":"{station}","time_ns":%d,"samples":['
            + ",".join(texts[i : i + BATCH_SAMPLES])
            + "]"
            for i in range(0, len(texts), BATCH_SAMPLES)
        ]
        made = {t: template(t, station, now_ns, RUN_MARK) for t in ("events", "intensity")}
        summary = dataclasses.replace(
            template("runs", station, now_ns, RUN_MARK),
            tool_id=tool_id,
            process_intensity=1.5,
            events=3,
            samples=1000,
        )
        self.events = run_templated(made["events"])
        self.intensity = run_templated(made["intensity"])
        self.decision = run_templated(template("decision", station, now_ns, RUN_MARK)).encode()
        self.summary = run_templated(summary).encode()
        self.predictor = encode(template("predictor", station, now_ns))

    def batch(self, index: int, run_id: int, newest_ns: int, events: int = 0) -> bytes:
        """The run's ``index``-th batch, its newest sample at ``newest_ns``, 1 ms apart, with
        ``events`` stick-slip events and their intensities found in it."""
        samples = self.batches[index] % (newest_ns, *batch_ids(run_id, newest_ns))
        found = (
            f',"events":[{",".join([self.events % run_id] * events)}],'
            f'"intensities":[{",".join([self.intensity % run_id] * events)}]}}'
        )
        return (samples + found).encode()

    def tool(self, run_id: int, state: str, now_ns: int) -> bytes:
        return (
            f'{{"station":"{self.station}","run_id":{run_id},"tool_id":{self.tool_id},"program_id":1,'
            f'"state":"{state}","time_ns":{now_ns}}}'
        ).encode()


class Station(StationPayloads):
    """One synthetic edge station's publishers and pre-encoded messages."""

    def __init__(
        self, session: zenoh.Session, station: LoadedStation, rows: list, per_sample: bool
    ) -> None:
        now = time.time_ns()
        super().__init__(station.station_id, station.config.station.tool_id, rows, now)
        self.put = {  # as the station's publisher: each channel's options (BLOCK: never lossy)
            channel.topic: declare_channel(session, channel, self.station).put
            for channel in STATION_CHANNELS
        }
        self.per_sample = per_sample
        self.published = 0
        self.started_ns = now

    def put_tool(self, run_id: int, state: str, now_ns: int) -> None:
        self.put[channels.TOOL.topic](self.tool(run_id, state, now_ns))

    def bus(self, now_ns: int) -> None:
        stats = BusStats(self.station, now_ns, 0, self.published, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0)
        self.put[channels.BUS.topic](encode(dataclasses.replace(stats, started_ns=self.started_ns)))


def events_in(newest: int) -> int:
    """Events found in the batch whose newest sample is the run's ``newest``-th: an event every
    :data:`EVENT_EVERY_TICKS` samples, each riding in the batch in progress (as an edge
    station's publisher puts them, :mod:`shared.runtime.sample_batching`)."""
    return sum(
        1 for n in range(newest - BATCH_SAMPLES + 1, newest + 1) if n % EVENT_EVERY_TICKS == 0
    )


def batch_ids(run_id: int, newest_ns: int) -> list[int]:
    """(run id, time) of each sample of a batch whose newest sample is ``newest_ns``."""
    ids: list[int] = []
    for k in range(BATCH_SAMPLES - 1, -1, -1):
        ids += (run_id, newest_ns - k * 1_000_000)
    return ids


def generate(endpoint: str, station_files: list[str], seconds: float, per_sample: bool) -> int:
    """Publish the runs of the stations of ``station_files`` (each its id and tool) for
    ``seconds`` or until SIGTERM (the run in progress is finished first), then each station's
    last BusStats."""
    stopped = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stopped.set())
    rows = run_rows()
    behind = 0
    with zenoh.open(zenoh_config("client", [endpoint])) as session:
        loaded = [load_station(Path(file)) for file in station_files]
        stations = [Station(session, station, rows, per_sample) for station in loaded]
        time.sleep(1.0)  # the router learns the subscribers
        end = time.monotonic() + seconds
        run_id = int(time.time()) * 1000
        tick = 0
        next_tick = time.perf_counter()
        while time.monotonic() < end and not stopped.is_set():
            run_id += 1
            now_ns = time.time_ns()
            for station in stations:
                station.put_tool(run_id, "running", now_ns)
            for n in range(len(rows)):
                now_ns = time.time_ns()
                for station in stations:
                    if per_sample:
                        station.put[channels.SAMPLES.topic](station.samples[n] % (run_id, now_ns))
                        station.published += 1
                        if n % EVENT_EVERY_TICKS == 0:  # alone, as a line-placed station
                            station.put[channels.EVENTS.topic]((station.events % run_id).encode())
                            intensity = (station.intensity % run_id).encode()
                            station.put[channels.INTENSITY.topic](intensity)
                    elif n % BATCH_SAMPLES == BATCH_SAMPLES - 1:
                        batch = station.batch(n // BATCH_SAMPLES, run_id, now_ns, events_in(n))
                        station.put[channels.SAMPLE_BATCHES.topic](batch)
                        station.published += BATCH_SAMPLES
                    if tick % 1000 == 0:
                        station.bus(now_ns)
                        station.put[channels.PREDICTOR.topic](station.predictor)
                tick += 1
                next_tick += 1e-3
                delay = next_tick - time.perf_counter()
                if delay > 0:
                    time.sleep(delay)
                else:
                    behind += 1
            now_ns = time.time_ns()
            for station in stations:
                station.put[channels.DECISION.topic](station.decision % run_id)
                station.put_tool(run_id, "done", now_ns)
                station.put[channels.RUNS.topic](station.summary % run_id)
            time.sleep(RUN_PAUSE_TICKS / 1e3)
            next_tick = time.perf_counter()
        for station in stations:
            station.bus(time.time_ns())
    published = sum(s.published for s in stations)
    print(f"generator: {published} samples, {behind} ticks behind schedule", flush=True)
    return 0


# -- the benchmark --------------------------------------------------------------------------


@dataclass
class RecorderHeard:
    """The recorder's RecorderStats of every station, as published once a second."""

    lag_p50_ms: list[float] = field(default_factory=list)
    lag_max_ms: list[float] = field(default_factory=list)
    missing: dict[str, int] = field(default_factory=dict)
    bad_payloads: dict[str, int] = field(default_factory=dict)
    listening: bool = False
    lock: threading.Lock = field(default_factory=threading.Lock)

    def on_stats(self, sample: zenoh.Sample) -> None:
        stats = decode(RecorderStats, sample.payload.to_bytes())
        with self.lock:
            self.missing[stats.station] = stats.missing_samples
            self.bad_payloads[stats.station] = stats.bad_payloads
            if not self.listening:
                return
            if stats.lag_p50_ms is not None:
                self.lag_p50_ms.append(stats.lag_p50_ms)
            if stats.lag_max_ms is not None:
                self.lag_max_ms.append(stats.lag_max_ms)


def wait_alive(
    session: zenoh.Session, expected: set[tuple[str, str]], processes: list, folder: Path
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
            raise SystemExit(f"not alive after {START_TIMEOUT_S:.0f} s: {sorted(missing)[:5]}")
        time.sleep(0.2)


def cpu_s(process: subprocess.Popen[bytes]) -> float:
    """User + system CPU seconds of a running process (Linux /proc)."""
    fields = Path(f"/proc/{process.pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def bench(
    stations: int, runs: int, rerun: bool, per_sample: bool, repo: Path, folder: Path
) -> dict[str, object]:
    port = free_tcp_port()
    base = write_station(folder, zenoh_port=port, replacements=EDGE_PROGRAM)
    paths = derive_stations(base, stations + 1, folder / "stations")
    real = load_station(paths[0])
    endpoint = f"tcp/127.0.0.1:{port}"
    processes: list[subprocess.Popen[bytes]] = []
    line = RecorderHeard()
    synthetic = [p.stem for p in paths[1:]]
    files = [str(p) for p in paths]
    try:
        processes.append(serve(["router", "--listen", endpoint], folder / "router.log", repo))
        recorder_args = ["recorder", "--config", *files] + ([] if rerun else ["--no-rerun"])
        recorder = serve(recorder_args, folder / "recorder.log", repo)
        processes.append(recorder)
        acquisition_args = ["acquisition", "--config", str(paths[0])]
        processes.append(serve(acquisition_args, folder / "acquisition.log", repo))
        with (
            zenoh.open(zenoh_config("client", [endpoint])) as session,
            StopListener(real.config.can, StationDatabase(real.dbc_path)) as listener,
        ):
            heard = Listener(session, REAL_STATION, TOPICS)
            subscriber = session.declare_subscriber(channels.RECORDER.key("*"), line.on_stats)
            expected = {(s, "recorder") for s in [REAL_STATION, *synthetic]}
            expected |= {(REAL_STATION, "acquisition"), (REAL_STATION, "predictor")}
            wait_alive(session, expected, processes, folder)
            cpu_before = cpu_s(recorder)
            with (folder / "generator.log").open("wb") as out:
                generator = subprocess.Popen(
                    [sys.executable, __file__, "--generate", endpoint, "--seconds", "3600"]
                    + (["--per-sample"] if per_sample else [])
                    + files[1:],
                    cwd=REPO,
                    stdout=out,
                    stderr=subprocess.STDOUT,
                )
            processes.append(generator)
            time.sleep(3.0)  # the load is on before the measured runs
            with line.lock:
                line.listening = True
            rig_args = ["rig", "--config", str(paths[0]), "--runs", str(runs), "--program", "1"]
            _, elapsed_s = tighten(rig_args, folder / "rig.log", runs, heard, processes)
            with line.lock:
                line.listening = False
            stop_process(generator, grace_s=10.0)
            time.sleep(3.0)  # the last batches filed, the last BusStats counted and reported
            cpu_used = cpu_s(recorder) - cpu_before
            heard.close()
            subscriber.undeclare()
            stops = listener.heard
    finally:
        for process in reversed(processes):
            stop_process(process, grace_s=10.0)
    rows, notes = figures(heard, stops)
    real_samples = sum(s.samples for s in summaries_of(heard).values())
    stop_ms = [r.stop_path_ms for r in rows]
    generator_note = (folder / "generator.log").read_text().strip()
    published = re.search(r"generator: (\d+) samples", generator_note)
    samples = (int(published.group(1)) if published else 0) + real_samples
    us = cpu_used / samples * 1e6 if samples else float("nan")
    with line.lock:
        missing = sum(line.missing.values())
        lag_p50 = statistics.median(line.lag_p50_ms) if line.lag_p50_ms else float("nan")
        lag_p99 = float(np.percentile(line.lag_max_ms, 99)) if line.lag_max_ms else float("nan")
        reported = len(line.missing)
        bad = sum(line.bad_payloads.values())
    p50, p90, p99 = np.percentile(stop_ms, [50, 90, 99]) if stop_ms else [float("nan")] * 3
    return {
        "stations": stations,
        "recorder_cpu_us_per_sample": round(us, 2),
        "stations_per_recorder_core": round(1e3 / us) if samples else None,
        "recorder_lag_p50_ms": round(lag_p50, 1),
        "recorder_lag_p99_ms": round(lag_p99, 1),
        "samples_missing": missing,
        "stations_reported": reported,
        "bad_payloads": bad,
        "stop_path_p50_ms": round(float(p50), 3),
        "stop_path_p90_ms": round(float(p90), 3),
        "stop_path_p99_ms": round(float(p99), 3),
        "stop_path_max_ms": round(max(stop_ms), 3) if stop_ms else None,
        "real_station_runs": f"{len(rows)} stops of {runs} runs ({elapsed_s:.0f} s)",
        "samples_recorded": samples,
        "generator": generator_note,
        "notes": notes,
    }


def goals_missed(result: dict[str, object]) -> list[str]:
    """What the result misses (nothing lost anywhere; the per-sample cost; N = 50's)."""
    missed = []
    if result["samples_missing"] != 0:
        missed.append(f"{result['samples_missing']} samples missing")
    if result["stations_reported"] != int(str(result["stations"])) + 1:
        missed.append(f"RecorderStats of {result['stations_reported']} stations only")
    us = float(str(result["recorder_cpu_us_per_sample"]))
    if not us <= GOAL_US_PER_SAMPLE:
        missed.append(f"recorder {us} µs per sample (goal <= {GOAL_US_PER_SAMPLE})")
    if result["stations"] == 50:
        lag = float(str(result["recorder_lag_p99_ms"]))
        if not lag <= GOAL_LAG_P99_MS:
            missed.append(f"recorder lag p99 {lag} ms (goal <= {GOAL_LAG_P99_MS})")
        p90 = float(str(result["stop_path_p90_ms"]))
        if not p90 <= GOAL_STOP_P90_MS:
            missed.append(f"stop path p90 {p90} ms (goal <= {GOAL_STOP_P90_MS})")
    return missed


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--stations", type=int, nargs="+", default=[50, 100])
    parser.add_argument("--runs", type=int, default=20, help="measured runs of st1 per N")
    parser.add_argument("--no-rerun", action="store_true", help="the recorder writes MCAP only")
    parser.add_argument("--per-sample", action="store_true", help="one message per sample")
    parser.add_argument("--repo", type=Path, default=REPO, help="checkout that runs the line")
    parser.add_argument("--keep", type=Path, default=None, help="keep files and logs here")
    parser.add_argument("--generate", default=None, help=argparse.SUPPRESS)
    parser.add_argument("--seconds", type=float, default=0.0, help=argparse.SUPPRESS)
    parser.add_argument("files", nargs="*", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.generate:
        return generate(args.generate, args.files, args.seconds, args.per_sample)
    failed = False
    for count in args.stations:
        with tempfile.TemporaryDirectory(prefix=f"bench-line-{count}-") as tmp:
            folder = args.keep / f"n{count}" if args.keep else Path(tmp)
            folder.mkdir(parents=True, exist_ok=True)
            result = bench(
                count, args.runs, not args.no_rerun, args.per_sample, args.repo.resolve(), folder
            )
        missed = goals_missed(result)
        failed = failed or bool(missed)
        print(f"N={count} (+ st1 real):")
        for key, value in result.items():
            print(f"  {key}: {value}")
        print(f"  goals: {'MISSED: ' + '; '.join(missed) if missed else 'met'}")
        sys.stdout.flush()
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
