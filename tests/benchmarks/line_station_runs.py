"""One station's runs through the real processes, as the line benchmarks drive them.

What ``bench_line.py`` and ``bench_line_inbox.py`` share (the stop path is measured on
its own by ``bench_stop_path.py``):
a short program, what is heard of each run on zenoh, the rig driven for N
runs, and the stop path per run (StopCommand heard minus the deciding
sample's receive time, both kernel timestamps).
"""

from __future__ import annotations

import subprocess
import time
from dataclasses import dataclass
from pathlib import Path

from shared.contract import RunSummary, StickSlipEvent, StopDecision, channels
from tests.support.can_injector import HeardStop
from tests.support.listener import Listener
from tests.support.station_files import serve

#: The short program: program 1 of the embedded station, to a lower preload, faster.
SHORT_PROGRAM = {
    # the line benchmarks measure the line predictor: one process serves every station
    "[predictor]\n": '[predictor]\nplacement = "line"\n',
    "target_force_n = 56000.0": "target_force_n = 24000.0",
    "motor_speed_rad_s = 0.5": "motor_speed_rad_s = 1.0",
}
RUN_TIMEOUT_S = 15.0  # per run, generous on a loaded machine


#: what the line benchmarks hear of the real station on zenoh (:class:`Listener`)
TOPICS = (channels.DECISION.topic, channels.EVENTS.topic, channels.RUNS.topic)


def summaries_of(heard: Listener) -> dict[int, RunSummary]:
    """The summary of each run heard (the last, were one heard twice), by run id."""
    return {summary.run_id: summary for summary in heard.of(channels.RUNS.topic)}


def tighten(
    rig_args: list[str],
    log: Path,
    runs: int,
    heard: Listener,
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
    while len(summaries_of(heard)) < runs and time.monotonic() < deadline:
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


def lead_ms(decision: StopDecision, events: list[StickSlipEvent], stop_s: float) -> float | None:
    """Predicted next slip minus the StopCommand's time, both since run start (ms)."""
    before = [e for e in events if e.time_s <= decision.time_s and e.predictions]
    if not before:
        return None
    ahead = [p.time_s for p in before[-1].predictions if p.time_s > stop_s]
    return (min(ahead) - stop_s) * 1e3 if ahead else None


def figures(heard: Listener, stops: list[HeardStop]) -> tuple[list[RunFigures], list[str]]:
    summaries = summaries_of(heard)
    # the first decision of each run (the acquisition acts on the first)
    decisions = {d.run_id: d for d in reversed(heard.of(channels.DECISION.topic))}
    events: dict[int, list[StickSlipEvent]] = {}
    for event in heard.of(channels.EVENTS.topic):
        events.setdefault(event.run_id, []).append(event)
    out: list[RunFigures] = []
    notes: list[str] = []
    first_stop: dict[int, HeardStop] = {}
    for stop in stops:
        first_stop.setdefault(stop.run_id, stop)
    extra = len(stops) - len(first_stop)
    if extra:
        notes.append(f"{extra} StopCommand(s) beyond one per run")
    for run_id in sorted(summaries):
        decision = decisions.get(run_id)
        heard_stop = first_stop.get(run_id)
        if decision is None or heard_stop is None:
            ended = summaries[run_id].tool_state
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
                lead_ms(decision, events.get(run_id, []), stop_s),
            )
        )
    return out, notes
