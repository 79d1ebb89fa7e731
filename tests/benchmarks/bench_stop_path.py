"""Stop-path latency: CAN sample in -> StopCommand back on the CAN bus, over real processes.

Run on demand (not collected by pytest)::

    .venv/bin/python tests/benchmarks/bench_stop_path.py [--runs 30]

The router, acquisition and predictor run as ``boltwatch serve`` processes on
an isolated station file (own zenoh port, own udp_multicast port); the rig
runs as ``boltwatch serve rig --runs N`` with a short program (lower target,
faster motor) so that N runs take about a second each. The benchmark listens
on the same CAN bus for StopCommand frames and on zenoh for decisions and
events. Per run it reports:

- ``stop path``: StopCommand receive time on the benchmark's CAN socket minus
  ``StopDecision.time_ns`` (the CAN receive time of the deciding sample in
  the acquisition). Both are kernel receive timestamps (SO_TIMESTAMPNS,
  CLOCK_REALTIME) of the same host, so they compare directly;
- its two halves: ``decide`` = ``decided_ns - time_ns`` (sample in, through
  zenoh to the predictor and through the core, until the decision is
  published) and ``act`` = StopCommand heard minus ``decided_ns`` (zenoh to
  the acquisition, CAN send, multicast delivery);
- ``lead``: from the StopCommand to the next stick-slip event that the last
  event before the decision predicted (``Prediction.time_s``, horizon 1, or
  the first prediction still ahead). This is the predictor's own forecast,
  not the rig's ground truth, which the rig does not publish.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import zenoh

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from services.cli.station_supervisor import stop_process  # noqa: E402
from shared import keys  # noqa: E402
from shared.can_database import StationDatabase  # noqa: E402
from shared.codec import decode  # noqa: E402
from shared.config import load_station  # noqa: E402
from shared.messages import RunSummary, StickSlipEvent, StopDecision  # noqa: E402
from shared.zenoh_session import zenoh_config  # noqa: E402
from tests.system.can_injector import HeardStop, StopListener  # noqa: E402
from tests.system.station_files import free_tcp_port, serve, write_station  # noqa: E402

STATION = "st1"
#: The short program: program 1 of the embedded station, to a lower preload, faster.
SHORT_PROGRAM = {
    "target_force_n = 56000.0": "target_force_n = 24000.0",
    "motor_speed_rad_s = 0.5": "motor_speed_rad_s = 1.0",
}
START_TIMEOUT_S = 30.0
RUN_TIMEOUT_S = 15.0  # per run, generous on a loaded machine


@dataclass
class Heard:
    decisions: dict[int, StopDecision] = field(default_factory=dict)
    events: dict[int, list[StickSlipEvent]] = field(default_factory=dict)
    summaries: dict[int, RunSummary] = field(default_factory=dict)
    lock: threading.Lock = field(default_factory=threading.Lock)

    def on_sample(self, sample: zenoh.Sample) -> None:
        topic = str(sample.key_expr).rsplit("/", 1)[-1]
        payload = sample.payload.to_bytes()
        with self.lock:
            if topic == keys.DECISION:
                decision = decode(StopDecision, payload)
                self.decisions.setdefault(decision.run_id, decision)
            elif topic == keys.EVENTS:
                event = decode(StickSlipEvent, payload)
                self.events.setdefault(event.run_id, []).append(event)
            elif topic == keys.RUNS:
                summary = decode(RunSummary, payload)
                self.summaries[summary.run_id] = summary


def tighten(
    rig_args: list[str],
    log: Path,
    runs: int,
    heard: Heard,
    processes: list[subprocess.Popen[bytes]],
    run_timeout_s: float = RUN_TIMEOUT_S,
) -> tuple[subprocess.Popen[bytes], float]:
    """Serve the rig (added to ``processes``) until its ``runs`` end, then wait up to
    5 s for their summaries; the rig's process and the seconds it all took."""
    rig = serve(rig_args, log)
    processes.append(rig)
    started = time.monotonic()
    rig.wait(timeout=run_timeout_s * runs)
    deadline = time.monotonic() + 5.0
    while len(heard.summaries) < runs and time.monotonic() < deadline:
        time.sleep(0.1)
    return rig, time.monotonic() - started


@dataclass(frozen=True)
class RunFigures:
    run_id: int
    reason: str
    stop_path_ms: float
    decide_ms: float
    act_ms: float
    lead_ms: float | None


def wait_alive(session: zenoh.Session, services: set[str], processes: list[Path]) -> None:
    deadline = time.monotonic() + START_TIMEOUT_S
    missing = set(services)
    while missing:
        for reply in session.liveliness().get(keys.health_key(STATION, "*")):
            if reply.ok is not None:
                missing.discard(str(reply.ok.key_expr).rsplit("/", 1)[-1])
        if time.monotonic() > deadline:
            logs = ", ".join(str(p) for p in processes)
            raise SystemExit(f"not alive after {START_TIMEOUT_S:.0f} s: {missing} (logs: {logs})")
        time.sleep(0.1)


def lead_ms(decision: StopDecision, events: list[StickSlipEvent], stop_s: float) -> float | None:
    """Predicted next slip minus the StopCommand's time, both since run start (ms)."""
    before = [e for e in events if e.time_s <= decision.time_s and e.predictions]
    if not before:
        return None
    ahead = [p.time_s for p in before[-1].predictions if p.time_s > stop_s]
    return (min(ahead) - stop_s) * 1e3 if ahead else None


def figures(heard: Heard, stops: list[HeardStop]) -> tuple[list[RunFigures], list[str]]:
    out: list[RunFigures] = []
    notes: list[str] = []
    first_stop: dict[int, HeardStop] = {}
    for stop in stops:
        first_stop.setdefault(stop.run_id, stop)
    extra = len(stops) - len(first_stop)
    if extra:
        notes.append(f"{extra} StopCommand(s) beyond one per run")
    for run_id in sorted(heard.summaries):
        decision = heard.decisions.get(run_id)
        heard_stop = first_stop.get(run_id)
        if decision is None or heard_stop is None:
            ended = heard.summaries[run_id].tool_state
            notes.append(
                f"run {run_id}: decision={decision is not None} stop heard="
                f"{heard_stop is not None} ({ended})"
            )
            continue
        stop_path_ns = heard_stop.received_ns - decision.time_ns
        stop_s = decision.time_s + stop_path_ns / 1e9
        out.append(
            RunFigures(
                run_id,
                decision.reason,
                stop_path_ns / 1e6,
                (decision.decided_ns - decision.time_ns) / 1e6,
                (heard_stop.received_ns - decision.decided_ns) / 1e6,
                lead_ms(decision, heard.events.get(run_id, []), stop_s),
            )
        )
    return out, notes


def table(rows: list[RunFigures]) -> str:
    def line(name: str, values: list[float]) -> str:
        if not values:
            return f"{name:<26}{'-':>8}"
        p50, p90, p99 = np.percentile(values, [50, 90, 99])
        cells = (p50, p90, p99, max(values), min(values), statistics.fmean(values))
        return f"{name:<26}" + "".join(f"{v:>8.2f}" for v in cells) + f"{len(values):>6}"

    header = f"{'ms':<26}" + "".join(f"{h:>8}" for h in ("p50", "p90", "p99", "max", "min", "mean"))
    leads = [r.lead_ms for r in rows if r.lead_ms is not None]
    return "\n".join(
        [
            header + f"{'n':>6}",
            line("stop path (sample->CAN)", [r.stop_path_ms for r in rows]),
            line("  decide (sample->decision)", [r.decide_ms for r in rows]),
            line("  act (decision->CAN)", [r.act_ms for r in rows]),
            line("lead (CAN stop->next slip)", leads),
        ]
    )


def run(runs: int, folder: Path) -> int:
    port = free_tcp_port()
    path = write_station(folder, zenoh_port=port, replacements=SHORT_PROGRAM)
    station = load_station(path)
    database = StationDatabase(station.dbc_path)
    endpoint = f"tcp/127.0.0.1:{port}"
    logs = {name: folder / f"{name}.log" for name in ("router", "acquisition", "predictor", "rig")}
    processes: list[subprocess.Popen[bytes]] = []
    heard = Heard()
    try:
        processes.append(serve(["router", "--listen", endpoint], logs["router"]))
        for name in ("acquisition", "predictor"):
            processes.append(serve([name, "--config", str(path)], logs[name]))
        with (
            zenoh.open(zenoh_config("client", [endpoint])) as session,
            StopListener(station.config.can, database) as listener,
        ):
            subscriber = session.declare_subscriber(keys.station_key(STATION, "*"), heard.on_sample)
            try:
                wait_alive(session, {"acquisition", "predictor"}, list(logs.values()))
                first_run_id = int(time.time())
                rig_args = ["rig", "--config", str(path), "--runs", str(runs)]
                rig_args += ["--program", "1", "--first-run-id", str(first_run_id)]
                rig, elapsed_s = tighten(rig_args, logs["rig"], runs, heard, processes)
            finally:
                subscriber.undeclare()
            stops = listener.heard
    finally:
        for process in reversed(processes):
            stop_process(process, grace_s=10.0)

    with heard.lock:
        rows, notes = figures(heard, stops)
    reasons = Counter(r.reason for r in rows)
    print(f"stop path over {len(rows)} of {runs} runs ({elapsed_s:.0f} s), reasons {dict(reasons)}")
    print(table(rows))
    errors = [abs(s.error_pct) for s in heard.summaries.values() if s.error_pct is not None]
    if errors:
        print(
            f"|reached - target| / target: median {statistics.median(errors):.2f} %, "
            f"max {max(errors):.2f} % over {len(errors)} runs"
        )
    for note in notes:
        print("note:", note)
    if rig.returncode != 0:
        print(f"rig exited {rig.returncode}, see {logs['rig']}")
    return 0 if rows else 1


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=30, help="tightening runs (default 30)")
    parser.add_argument("--keep", type=Path, default=None, help="keep station file and logs here")
    args = parser.parse_args(argv)
    if args.keep is not None:
        args.keep.mkdir(parents=True, exist_ok=True)
        return run(args.runs, args.keep)
    with tempfile.TemporaryDirectory(prefix="bench-stop-path-") as folder:
        return run(args.runs, Path(folder))


if __name__ == "__main__":
    sys.exit(main())
