"""Stop path: CAN sample in -> StopCommand on the CAN bus, over the real processes (not a test).

Run on demand::

    .venv/bin/python tests/benchmarks/bench_stop_path.py [--stops 1000]
        [--placement edge|line|before] [--repo PATH] [--stations N] [--spindles N]

The whole simulated station runs as ``boltwatch serve`` processes on an
isolated station file (own zenoh and udp_multicast ports): the router, the
recorder, the acquisition (with the station's predictor on its CAN thread,
``--placement edge``, the default; or a separate ``serve predictor``,
``--placement line``, the layout before the edge stop path) and the rig. The
rig plays two programs, half the stops each:

- **hard limit**: the acquisition's station file gives the program a torque
  limit of 60 Nm, the rig's own file 320 Nm: the predictor stops the tool on
  ``torque_limit`` (two samples over it) long before the rig's own limit;
- **plateau**: a preload target 4 kN above the start, so every run ends on a
  plateau decision (``plateau_closest``) or the target (``target_reached``).

Per stop: the StopCommand's kernel receive time on this benchmark's CAN
socket minus ``StopDecision.time_ns``, the kernel receive time in the
acquisition of the sample that decided (both CLOCK_REALTIME on one host).
Reported: p50 / p90 / p99 / max over all stops and per kind, the stops lost
(a decision with no StopCommand heard, or a run the rig ended by itself),
and what the machine itself lost meanwhile: the steal column of
``/proc/stat`` (the host's share of this VM's CPU time).

``--backlog N``: each station's spool holds N old batches of samples at the
start, never acknowledged: its acquisition sends them again (at
``drain_messages_per_s``) while the stops are measured, the stop path
beside a draining spool.

``--spindles N``: a multi-spindle station of N spindles on one bus (the rig's
synchronised cycles, each spindle its own run and its own StopCommand id):
each cycle is N stops, reported per spindle too. Beside the stop path, the
CPU the recorder and the acquisition used while the stops ran, per sample
recorded (``/proc/<pid>/stat``, user + system, over the samples the runs'
summaries count).

``--stations N``: a line of N stations (derived as ``boltwatch up
--stations`` derives them), each with its own tool and bus, on one router
and one recorder; the stops split evenly. ``--repo PATH`` starts the
services from another checkout (the code before a change, side by side);
the benchmark's own code (files, listener) stays this one's.
"""

from __future__ import annotations

import argparse
import contextlib
import statistics
import subprocess
import sys
import tempfile
import time
from collections import Counter
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
    StationDatabase,
    channels,
    encode,
    keys,
)
from shared.runtime import zenoh_config
from shared.spool import SpoolFile
from tests.support.can_injector import HeardStop, StopListener
from tests.support.fuzz.payloads import template
from tests.support.listener import Listener
from tests.support.station_files import free_tcp_port, write_station
from tests.support.station_files import serve as serve_process

STATION = "st1"
HARD_LIMIT_PROGRAM, PLATEAU_PROGRAM = 1, 2
#: both programs start at 10 kN and move fast: a run lasts about a tenth of a second
PROGRAMS = """
[[programs]]
id = 1
name = "hard limit"
target_force_n = 70000.0
motor_speed_rad_s = 1.0
start_force_n = 10000.0
max_torque_nm = {torque_limit_nm}
max_force_n = 75000.0
max_angle_deg = 150.0
max_time_s = 3.0

[[programs]]
id = 2
name = "plateau"
target_force_n = 14000.0
motor_speed_rad_s = 1.0
start_force_n = 10000.0
max_torque_nm = 320.0
max_force_n = 75000.0
max_angle_deg = 150.0
max_time_s = 3.0
"""
ACQUISITION_TORQUE_LIMIT_NM = 60.0
RIG_TORQUE_LIMIT_NM = 320.0
START_TIMEOUT_S = 30.0


def station_files(folder: Path, placement: str, spindles: int = 1) -> tuple[Path, Path]:
    """(the services' station file, the rig's): the same station, the rig's limits higher."""
    port = free_tcp_port()
    common = {"pause_between_runs_s = 0.3": "pause_between_runs_s = 0.05"}
    if spindles > 1:
        common["has_force_sensor = true"] = f"has_force_sensor = true\nspindles = {spindles}"
    if placement != "before":  # a checkout from before the key knows only the line's predictor
        common["[predictor]\nwindow_samples = 5"] = (
            f'[predictor]\nplacement = "{placement}"\nwindow_samples = 5'
        )
    services = write_station(folder, zenoh_port=port, replacements=common)
    text = services.read_text()
    start = text.index("[[programs]]")
    end = text.index("[predictor]")
    programs = text[start:end]
    services.write_text(
        text.replace(programs, PROGRAMS.format(torque_limit_nm=ACQUISITION_TORQUE_LIMIT_NM) + "\n")
    )
    rig = folder / "rig.toml"
    rig.write_text(
        services.read_text().replace(
            f"max_torque_nm = {ACQUISITION_TORQUE_LIMIT_NM}",
            f"max_torque_nm = {RIG_TORQUE_LIMIT_NM}",
        )
    )
    return services, rig


def cpu_times() -> tuple[int, int]:
    """(all CPU time, of it stolen by the host), in USER_HZ ticks since boot."""
    fields = [int(v) for v in Path("/proc/stat").read_text().splitlines()[0].split()[1:]]
    return sum(fields[:8]), fields[7]


def wait_alive(session: zenoh.Session, station_id: str, logs: list[Path]) -> None:
    deadline = time.monotonic() + START_TIMEOUT_S
    missing = {"recorder", "acquisition", "predictor"}
    while missing:
        for reply in session.liveliness().get(keys.health_key(station_id, "*")):
            if reply.ok is not None:
                missing.discard(str(reply.ok.key_expr).rsplit("/", 1)[-1])
        if time.monotonic() > deadline:
            raise SystemExit(f"not alive after {START_TIMEOUT_S:.0f} s: {missing} (logs {logs})")
        time.sleep(0.1)


@dataclass(frozen=True)
class Stop:
    station: str
    run_id: int
    program: int
    reason: str
    path_ms: float  # StopCommand heard - deciding sample received
    spindle: int | None = None  # a multi-spindle station's


def process_cpu_s(pid: int) -> float:
    """The CPU time (user + system) process ``pid`` used so far, seconds."""
    import os

    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def stops_of(
    heard: Listener, stops: dict[str, list[HeardStop]], programs: dict[tuple[str, int], int]
) -> tuple[list[Stop], list[str]]:
    # the first decision of each run (the acquisition acts on the first), the last summary
    decisions = {(d.station, d.run_id): d for d in reversed(heard.of(channels.DECISION.topic))}
    summaries = {(s.station, s.run_id): s for s in heard.of(channels.RUNS.topic)}
    first: dict[tuple[str, int], HeardStop] = {}
    for station, heard_stops in stops.items():
        for stop in heard_stops:
            first.setdefault((station, stop.run_id), stop)
    out, lost = [], []
    for (station, run_id), program in sorted(programs.items()):
        decision = decisions.get((station, run_id))
        summary = summaries.get((station, run_id))
        if decision is None:
            state = summary.tool_state if summary else "?"
            lost.append(f"{station} run {run_id}: no decision ({state})")
            continue
        heard_stop = first.get((station, run_id))
        if heard_stop is None:
            late = summary.late_decision if summary else None
            lost.append(
                f"{station} run {run_id}: {decision.reason} decided, no StopCommand (late: {late})"
            )
            continue
        path_ms = (heard_stop.received_ns - decision.time_ns) / 1e6
        spindle = summary.spindle if summary else None
        out.append(Stop(station, run_id, program, decision.reason, path_ms, spindle))
    return out, lost


def row(name: str, values: list[float]) -> str:
    if not values:
        return f"{name:<28}{'-':>8}"
    p50, p90, p99 = np.percentile(values, [50, 90, 99])
    cells = (p50, p90, p99, max(values), statistics.fmean(values))
    return f"{name:<28}" + "".join(f"{v:>8.3f}" for v in cells) + f"{len(values):>7}"


@dataclass
class Line:
    """The benchmark's line: station files, services, the programs of the runs."""

    args: argparse.Namespace
    folder: Path
    services_paths: list[Path]
    rig_paths: list[Path]
    processes: list[subprocess.Popen[bytes]] = field(default_factory=list)
    programs: dict[tuple[str, int], int] = field(default_factory=dict)
    pids: dict[str, int] = field(default_factory=dict)  # service -> its first process

    @property
    def stations(self) -> list[LoadedStation]:
        return [load_station(path) for path in self.services_paths]

    def serve(self, name: str, arguments: list[str]) -> subprocess.Popen[bytes]:
        process = serve_process(arguments, self.folder / f"{name}.log", self.args.repo.resolve())
        self.processes.append(process)
        self.pids.setdefault(name.split("-", 1)[0], process.pid)
        return process

    def start(self, endpoint: str) -> None:
        self.serve("router", ["router", "--listen", endpoint])
        configs = [str(path) for path in self.services_paths]
        self.serve("recorder", ["recorder", "--config", *configs, "--no-rerun"])
        if self.args.placement != "edge":
            self.serve("predictor", ["predictor", "--config", *configs])
        for path in self.services_paths:
            self.serve(f"acquisition-{path.stem}", ["acquisition", "--config", str(path)])

    def tighten(self, stations: list[LoadedStation]) -> None:
        """Every station's rig plays each program for its share of the stops, in parallel
        (a multi-spindle station: cycles of a run each spindle)."""
        first_run_id = int(time.time())
        spindles = self.args.spindles
        cycles = self.args.stops // (2 * len(stations) * spindles)
        per_program = cycles * spindles
        for index, program in enumerate((HARD_LIMIT_PROGRAM, PLATEAU_PROGRAM)):
            run_id = first_run_id + index * per_program
            rigs = []
            for station, rig_path in zip(stations, self.rig_paths, strict=True):
                name = f"rig-{station.station_id}-{program}"
                arguments = ["rig", "--config", str(rig_path), "--runs", str(cycles)]
                arguments += ["--program", str(program), "--first-run-id", str(run_id)]
                rigs.append((self.serve(name, arguments), name))
                for k in range(per_program):
                    self.programs[(station.station_id, run_id + k)] = program
            for rig, name in rigs:
                rig.wait(timeout=per_program * 3.0 + 60.0)
                if rig.returncode != 0:
                    raise SystemExit(f"{name} exited {rig.returncode}, see {self.folder}")

    def serve_pid(self, name: str) -> int:
        """The pid of the first ``serve <name>`` started (the first station's acquisition)."""
        return self.pids[name]

    def stop(self) -> None:
        for process in reversed(self.processes):
            stop_process(process, grace_s=10.0)


def fill_spool(station: LoadedStation, messages: int) -> None:
    """``messages`` batches of samples an hour old in the station's spool, never acknowledged:
    its acquisition sends them again while the stops are measured (a station draining)."""
    spool = SpoolFile(station.spool_folder / f"{station.station_id}-acquisition.sqlite")
    hour_ago_ns = time.time_ns() - 3600 * 1_000_000_000
    for n in range(messages):
        batch = template("sample_batches", station.station_id, hour_ago_ns + n * 50_000_000, 1)
        spool.append("sample_batches", encode(batch), 0, 1, len(batch.samples), hour_ago_ns)
    spool.close()


def run(args: argparse.Namespace, folder: Path) -> int:
    services_file, rig_file = station_files(folder, args.placement, args.spindles)
    line = Line(args, folder, [services_file], [rig_file])
    if args.stations > 1:
        line.services_paths = derive_stations(services_file, args.stations, folder / "services")
        line.rig_paths = derive_stations(rig_file, args.stations, folder / "rigs")
    stations = line.stations
    for station in stations if args.backlog else []:
        fill_spool(station, args.backlog)
    database = StationDatabase(stations[0].dbc_path)
    endpoint = stations[0].config.zenoh.connect[0]
    try:
        line.start(endpoint)
        with contextlib.ExitStack() as listening:
            session = listening.enter_context(zenoh.open(zenoh_config("client", [endpoint])))
            listeners = {
                s.station_id: listening.enter_context(
                    StopListener(
                        s.config.can, database, args.spindles, s.config.can.spindle_id_stride
                    )
                )
                for s in stations
            }
            topics = (channels.DECISION.topic, channels.RUNS.topic)
            heard = listening.enter_context(Listener(session, "*", topics))
            for station in stations:
                wait_alive(session, station.station_id, [folder])
            busy = {name: line.serve_pid(name) for name in ("recorder", "acquisition")}
            used_before = {name: process_cpu_s(pid) for name, pid in busy.items()}
            cpu_before, started = cpu_times(), time.monotonic()
            line.tighten(stations)
            elapsed_s, cpu_after = time.monotonic() - started, cpu_times()
            used = {name: process_cpu_s(pid) - used_before[name] for name, pid in busy.items()}
            time.sleep(2.0)  # the last summaries
            heard_stops = {station_id: listener.heard for station_id, listener in listeners.items()}
    finally:
        line.stop()
    stops, lost = stops_of(heard, heard_stops, line.programs)
    total, steal = (after - before for after, before in zip(cpu_after, cpu_before, strict=True))
    print(
        f"stop path, {len(stations)} station(s), placement {args.placement}, services from "
        f"{args.repo.resolve()}: {len(stops)} stops of {len(line.programs)} runs in "
        f"{elapsed_s:.0f} s; the host stole {100.0 * steal / total:.1f} % of this VM's CPU "
        "time meanwhile"
    )
    print_table(stops, [s.station_id for s in stations] if len(stations) > 1 else [])
    samples = sum(s.samples for s in heard.of(channels.RUNS.topic))
    if samples:
        print(
            f"CPU a sample over {samples} samples ({args.spindles} spindle(s)): "
            + ", ".join(f"{name} {1e6 * cpu_s / samples:.1f} µs" for name, cpu_s in used.items())
            + " (the first acquisition's; with --stations the recorder serves them all)"
        )
    print(f"lost: {len(lost)}")
    for note in lost[:20]:
        print("  ", note)
    return 0 if stops and not lost else 1


def print_table(stops: list[Stop], station_ids: list[str]) -> None:
    header = f"{'ms':<28}" + "".join(f"{h:>8}" for h in ("p50", "p90", "p99", "max", "mean"))
    print(header + f"{'n':>7}")
    print(row("all stops", [s.path_ms for s in stops]))
    for program, name in ((HARD_LIMIT_PROGRAM, "hard limit"), (PLATEAU_PROGRAM, "plateau")):
        print(row(f"  {name}", [s.path_ms for s in stops if s.program == program]))
    for station_id in station_ids:
        print(row(f"  {station_id}", [s.path_ms for s in stops if s.station == station_id]))
    for spindle in sorted({s.spindle for s in stops if s.spindle is not None}):
        print(row(f"  spindle {spindle}", [s.path_ms for s in stops if s.spindle == spindle]))
    print("reasons:", dict(Counter(s.reason for s in stops)))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--stops", type=int, default=1000, help="runs, each one stop (1000)")
    parser.add_argument(
        "--backlog",
        type=int,
        default=0,
        help="messages in each station's spool at the start, sent again while the stops are "
        "measured (a station draining after a cut; the spool is on by default)",
    )
    parser.add_argument(
        "--placement",
        choices=("edge", "line", "before"),
        default="edge",
        help="where the decision runs; 'before': a --repo from before [predictor] placement "
        "(a separate predictor, the station file without the key)",
    )
    parser.add_argument("--repo", type=Path, default=REPO, help="checkout to serve from")
    parser.add_argument(
        "--stations", type=int, default=1, help="stations on the line, each its own tool (1)"
    )
    parser.add_argument(
        "--spindles", type=int, default=1, help="spindles of each station, one bus (1)"
    )
    parser.add_argument("--keep", type=Path, default=None, help="keep files and logs here")
    args = parser.parse_args(argv)
    if args.keep is not None:
        args.keep.mkdir(parents=True, exist_ok=True)
        return run(args, args.keep)
    with tempfile.TemporaryDirectory(prefix="bench-stop-path-") as folder:
        return run(args, Path(folder))


if __name__ == "__main__":
    sys.exit(main())
