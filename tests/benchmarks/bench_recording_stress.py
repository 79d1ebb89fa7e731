"""The line's recording under stress (stations, router restarts, cable cuts), every payload checked.

Run on demand (not collected by pytest)::

    nice -n 5 .venv/bin/python tests/benchmarks/bench_recording_stress.py          # 500 k samples
    nice -n 5 .venv/bin/python tests/benchmarks/bench_recording_stress.py --full   # 10 M samples
    ... --netns   # the stations on hosts of their own (network namespaces), cables cut

One router and one ``serve recorder`` (MCAP only; ``--rerun``: and Rerun) for
``--stations`` synthetic edge stations (:mod:`tests.benchmarks.stress_stations`:
each a real :class:`~shared.runtime.queued_publisher.QueuedPublisher` with
batches, its spool on, or off for every ``--no-spool-every``-th; every
``--per-sample-every``-th puts each sample alone, as a station whose predictor
is on the line does) split over ``--generators`` processes and publishing
``--rate`` samples a second in all, and ``--real`` real stations (rig and
acquisition with its edge predictor on a ``udp_multicast`` CAN bus, spool on).
Every ``--restart-every-s`` the router is killed (SIGKILL) and started again
``--outage-s`` later, while the stations publish (not while their spools drain
afterwards). With ``--netns`` the line server and each generator and real
station are hosts of their own (:class:`tests.support.netns_line.Line`) and
every ``--cut-every-s`` one generator's cable is pulled for ``--cut-s``.

Afterwards every message of every MCAP file is read back and checked
(:mod:`tests.benchmarks.recording_check`): each decodes with its channel's
schema and names its topic's station, no channel is raw, no file is left
unfinished, and each sample's (station, run, sequence) is recorded once; a
spooling station's samples are all there, a real station's as many as its
last ``BusStats`` counted; a station without spool may lose what it published
while the router was down or its cable out (counted and printed). Exit
status 1 when any of that fails.
"""

from __future__ import annotations

import argparse
import json
import re
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from contextlib import ExitStack
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from services.cli.station_supervisor import stop_process
from shared.config import derive_stations
from tests.benchmarks.bench_line import EDGE_PROGRAM, cpu_s
from tests.benchmarks.recording_check import check_recordings
from tests.support.netns_line import LINE_ENDPOINT, Line, unavailable_reason
from tests.support.station_files import free_tcp_port, write_station

FULL_SAMPLES = 10_000_000
START_TIMEOUT_S = 120.0
LOG_WAIT_S = 60.0


class StressLine:
    """The line's processes (on this host, or in the namespaces of a :class:`Line`)."""

    def __init__(self, folder: Path, line: Line | None) -> None:
        self.folder = folder
        self.line = line
        self.processes: dict[str, subprocess.Popen[bytes]] = {}

    def start(self, name: str, host: int | None, command: Sequence[str]) -> None:
        """``command`` (``python -m ...`` arguments) as ``name``; ``host``: the station
        namespace's number with a line (None: the line server)."""
        log = (self.folder / f"{name}.log").open("ab")
        full = [sys.executable, *command]
        if self.line is None:
            process = subprocess.Popen(full, cwd=REPO, stdout=log, stderr=subprocess.STDOUT)
        else:
            namespace = self.line.server if host is None else self.line.station(host)
            process = self.line.popen(namespace, full, log, REPO)
        self.processes[name] = process

    def serve(self, name: str, host: int | None, args: Sequence[str]) -> None:
        self.start(name, host, ["-m", "services.cli", "serve", *args])

    def wait_log(
        self, name: str, pattern: str, timeout_s: float = LOG_WAIT_S, times: int = 1
    ) -> None:
        """Until ``name``'s log holds ``pattern`` ``times`` times (SystemExit when it died)."""
        deadline = time.monotonic() + timeout_s
        path = self.folder / f"{name}.log"
        while len(re.findall(pattern, path.read_text(errors="replace"))) < times:
            if self.processes[name].poll() is not None or time.monotonic() > deadline:
                raise SystemExit(f"{name} did not log {pattern!r}: see {path}")
            time.sleep(0.2)

    def stop(self, name: str, grace_s: float = 10.0) -> None:
        process = self.processes.pop(name, None)
        if process is not None:
            stop_process(process, grace_s=grace_s)

    def stop_all(self) -> None:
        for name in reversed(list(self.processes)):
            self.stop(name)

    def chaos(self, args: argparse.Namespace, endpoint: str) -> tuple[int, int]:
        """Kill and restart the router, pull cables (with a line), while the generators
        publish; then wait for them to drain their spools and end. (restarts, cuts)"""
        generators = [f"generator{g}" for g in range(args.generators)]
        published = [self.folder / f"manifest{g}.published" for g in range(args.generators)]
        next_restart = time.monotonic() + args.restart_every_s
        next_cut = time.monotonic() + args.cut_every_s
        restarts = cuts = 0
        while any(self.processes[g].poll() is None for g in generators):
            time.sleep(0.2)
            if all(path.exists() for path in published):
                continue  # every run published: the spools drain in peace
            now = time.monotonic()
            if args.restart_every_s and now >= next_restart:
                self.processes["router"].send_signal(signal.SIGKILL)
                self.processes["router"].wait(10)
                time.sleep(args.outage_s)
                self.serve("router", None, ["router", "--listen", endpoint])
                restarts += 1
                # the next outage is counted from the router's start: on a loaded machine a
                # Python process takes seconds to listen
                self.wait_log("router", "router listening", START_TIMEOUT_S, restarts + 1)
                next_restart = time.monotonic() + args.restart_every_s
            if self.line is not None and args.cut_every_s and now >= next_cut:
                host = cuts % args.generators + 1
                self.line.cut(host)
                time.sleep(args.cut_s)
                self.line.reconnect(host)
                cuts += 1
                next_cut = time.monotonic() + args.cut_every_s
        return restarts, cuts


def every(paths: Sequence[Path], step: int, offset: int) -> list[str]:
    """The ids of every ``step``-th station file from the ``offset``-th (none: step 0)."""
    return [path.stem for i, path in enumerate(paths) if step and i % step == offset]


def run(args: argparse.Namespace, folder: Path) -> dict[str, object]:
    line_context = Line(args.generators + args.real) if args.netns else None
    with ExitStack() as stack:
        line = stack.enter_context(line_context) if line_context is not None else None
        return _run(args, folder, line)
    raise AssertionError("unreachable")


def _run(args: argparse.Namespace, folder: Path, line: Line | None) -> dict[str, object]:
    port = 7447 if line is not None else free_tcp_port()
    replacements = dict(EDGE_PROGRAM)
    if line is not None:
        replacements["tcp/127.0.0.1:7447"] = LINE_ENDPOINT
    base = write_station(folder, zenoh_port=port, replacements=replacements)
    paths = derive_stations(base, args.stations + args.real, folder / "stations")
    endpoint = LINE_ENDPOINT if line is not None else f"tcp/127.0.0.1:{port}"
    real, synthetic = paths[: args.real], paths[args.real :]
    no_spool = every(synthetic, args.no_spool_every, args.no_spool_every - 1)
    per_sample = every(synthetic, args.per_sample_every, 0)
    stress = StressLine(folder, line)
    started = time.monotonic()
    try:
        stress.serve("router", None, ["router", "--listen", endpoint])
        stress.wait_log("router", "router listening", START_TIMEOUT_S)
        files = [str(p) for p in paths]
        stress.serve("recorder", None, ["recorder", "--config", *files]
                     + ([] if args.rerun else ["--no-rerun"]))  # fmt: skip
        stress.wait_log("recorder", r"recording boltwatch/", START_TIMEOUT_S)
        for index, path in enumerate(real, start=args.generators + 1):
            stress.serve(f"{path.stem}-acquisition", index, ["acquisition", "--config", str(path)])
        for index, path in enumerate(real, start=args.generators + 1):
            stress.wait_log(f"{path.stem}-acquisition", r"acquisition of \S+ on")
            rig = ["rig", "--config", str(path), "--runs", str(args.real_runs), "--program", "1"]
            stress.serve(f"{path.stem}-rig", index, rig)
        for g in range(args.generators):
            mine = [str(p) for p in synthetic[g :: args.generators]]
            command = ["-m", "tests.benchmarks.stress_stations", str(folder / f"manifest{g}.json"),
                       *mine, "--runs", str(args.runs), "--run-samples", str(args.run_samples),
                       "--rate", str(args.rate / args.generators),
                       "--no-spool", *no_spool, "--per-sample", *per_sample]  # fmt: skip
            stress.start(f"generator{g}", g + 1, command)
        restarts, cuts = stress.chaos(args, endpoint)
        for path in real:
            stress.processes[f"{path.stem}-rig"].wait(timeout=args.real_runs * 30)
        time.sleep(args.settle_s)  # real stations' spools drained, last batches filed
        for path in real:
            stress.stop(f"{path.stem}-acquisition")  # its last BusStats
        time.sleep(3.0)
        recorder_cpu_s = cpu_s(stress.processes["recorder"])
        stress.stop("recorder", grace_s=120.0)
    finally:
        stress.stop_all()
    elapsed_s = time.monotonic() - started
    manifest: dict[str, dict[str, Any]] = {}
    for g in range(args.generators):
        manifest |= json.loads((folder / f"manifest{g}.json").read_text())
    published = {s: {int(r): n for r, n in m["runs"].items()} for s, m in manifest.items()}
    check = check_recordings(base.parent / "recordings", published)
    result = check.summary()
    spooled_missing = {s: n for s, n in check.missing.items() if s not in no_spool and n}
    real_lost: dict[str, int | None] = {}
    real_recorded: dict[str, int] = {}
    for path in real:
        bus = check.last_bus.get(path.stem)
        recorded = sum(m.count(1) for (s, _), m in check.seen.items() if s == path.stem)
        real_recorded[path.stem] = recorded
        real_lost[path.stem] = None if bus is None else bus.samples - recorded
    recorder_log = (folder / "recorder.log").read_text(errors="replace")
    refused_line = re.findall(r"refused payloads per station, recorded raw: (.*)", recorder_log)
    published_samples = sum(int(str(m["published"])) for m in manifest.values())
    result |= {
        "stations": f"{args.stations} synthetic ({len(no_spool)} without spool, "
        f"{len(per_sample)} a message a sample) + {args.real} real",
        "netns": args.netns,
        "router_restarts": restarts,
        "cable_cuts": cuts,
        "published_samples_synthetic": published_samples,
        "dropped_or_failed": sum(
            int(str(m["dropped"])) + int(str(m["failed"])) for m in manifest.values()
        ),
        "missing_spooled": spooled_missing,
        "real_stations_recorded": real_recorded,
        "real_stations_lost": real_lost,
        "elapsed_s": round(elapsed_s, 1),
        "samples_per_s": round(check.samples / elapsed_s),
        "recorder_cpu_us_per_sample": round(recorder_cpu_s / max(check.samples, 1) * 1e6, 2),
        "recorder_refused": refused_line[-1] if refused_line else "nothing",
        "ok": check.ok
        and not spooled_missing
        and not any(real_lost.values())
        and all(v is not None for v in real_lost.values()),
    }
    return result


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--stations", type=int, default=50, help="synthetic edge stations")
    parser.add_argument("--runs", type=int, default=10, help="runs per synthetic station")
    parser.add_argument("--run-samples", type=int, default=1000, help="samples a run")
    parser.add_argument("--full", action="store_true", help=f"{FULL_SAMPLES:,} samples in all")
    parser.add_argument(
        "--rate", type=float, default=10_000.0, help="samples a second, all synthetic stations"
    )
    parser.add_argument("--generators", type=int, default=2, help="processes of the stations")
    parser.add_argument("--no-spool-every", type=int, default=5, help="0: every one spools")
    parser.add_argument("--per-sample-every", type=int, default=5, help="0: every one puts batches")
    parser.add_argument("--real", type=int, default=1, help="real stations (rig, acquisition)")
    parser.add_argument("--real-runs", type=int, default=20)
    parser.add_argument("--restart-every-s", type=float, default=20.0, help="0: never")
    parser.add_argument("--outage-s", type=float, default=2.0)
    parser.add_argument("--netns", action="store_true", help="hosts of their own, cables cut")
    parser.add_argument("--cut-every-s", type=float, default=30.0)
    parser.add_argument("--cut-s", type=float, default=5.0)
    parser.add_argument("--settle-s", type=float, default=10.0)
    parser.add_argument("--rerun", action="store_true", help="the recorder writes .rrd too")
    parser.add_argument("--keep", type=Path, default=None, help="keep files and logs here")
    args = parser.parse_args(argv)
    if args.full:
        args.runs = -(-FULL_SAMPLES // (args.stations * args.run_samples))
    # SIGTERM stops the children too (the line's processes are stopped in a finally)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(f"{parser.prog}: stopped by SIGTERM"))
    if args.netns and (why := unavailable_reason()) is not None:
        raise SystemExit(f"--netns: {why}")
    with tempfile.TemporaryDirectory(prefix="bench-stress-") as tmp:
        folder = args.keep or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        result = run(args, folder)
    for key, value in result.items():
        print(f"{key}: {value}")
    return 0 if result["ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
