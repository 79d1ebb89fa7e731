"""Stop accuracy closed loop and live: joints across the paper's ranges through the real processes.

Run on demand (not a test)::

    .venv/bin/python tests/benchmarks/bench_live_accuracy.py [--joints 100] [--torque-only]
        [--placement edge|line] [--final-share 0.1]

The joints are those of ``bench_predictor_accuracy.py`` (same draw, same
seed, same physics): k_e 200-2000 Nm/rad, k_s 30-180 kN/rad, μ_stick
0.1-0.4, motor speeds 0.1-2 rad/s, targets 30-60 kN. Each becomes a joint
file and a program of one station file (``programs[].joint``), so the live
predictor decides every run with its own joint, as a station does. The
services run as ``boltwatch serve`` processes: router, recorder and the
acquisition (the station's predictor on its CAN thread, ``--placement
edge``; or ``line``: a separate predictor over zenoh). The tool is the
project's real rig code (``services.rig.realtime.RealtimeRig``, at
real-time priority, in this process), one run per joint on the station's
udp_multicast bus: it sends each sample as CAN frames at 1 kHz, obeys a
``StopCommand`` at once, keeps its own conventional shutoff at the target and
its hard limits, and reports the settled true preload.

Per joint, |F_reached - F_target| / F_target of:

- **live**: the run above, through CAN, zenoh and the real processes;
- **offline replay**: the recorded run exported from its MCAP and predicted
  again with the station's settings (what ``boltwatch predict --config
  --program`` does); the joint simulated again (same seed) and halted at the
  sample that decided offline, or at the tool's own shutoff at the target if
  that comes first, as the live rig halts (it halts the moment a StopCommand
  arrives: live, a fraction of a millisecond after the deciding sample);
- **oracle**: the closest reachable end (``bench_predictor_accuracy.oracle``);
- **conventional**: the shutoff inside the tool controller, one sample of
  latency, no network (``bench_predictor_accuracy.conventional``).

Also printed: live = offline, the share of runs whose live decision was the
offline one (same reason at the same sample), and what stopped each run.
``--final-share S``: every program has a final stage at S of its speed, the
rig runs it (StageCommand over CAN: switch, pulses, finish) and the station
commands it; besides the rows above, **offline staged** is the same joint
tightened offline by the rig's controller and the core with that program
(``tests/support/staged_runs.py``), the figure the live one is held to.
``--torque-only``: the station has no force sensor and the programs target
the torque (the preload figures are then information, as in the offline
benchmark, and the torque figures are printed beside them).
"""

from __future__ import annotations

import argparse
import contextlib
import math
import statistics
import sys
import tempfile
import threading
import time
from collections import Counter
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import zenoh

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from services.cli.station_supervisor import stop_process
from services.rig.frames import RigFrames
from services.rig.realtime import RealtimeRig, ToolIdentity
from shared.config import (
    Program,
    RigSection,
    load_station,
)
from shared.contract import (
    StationDatabase,
    StopDecision,
    channels,
    read_trace,
)
from shared.model import JointConstants
from shared.recordings.mcap import export_trace
from shared.runtime import (
    RIG_PRIORITY,
    open_bus,
    use_realtime_priority,
    zenoh_config,
)
from shared.stickslip import (
    CoreDecision,
    PredictorCore,
    PredictorSettings,
    replay,
)
from tests.benchmarks.bench_predictor_accuracy import (
    Joint,
    conventional,
    draw_joint,
    error,
    finish,
    max_samples,
    oracle,
    physics,
    stats,
    torque_error,
)
from tests.benchmarks.bench_stop_path import wait_alive
from tests.benchmarks.joint_files import joint_toml
from tests.support.listener import Listener
from tests.support.staged_runs import StagedEnd, run_staged
from tests.support.station_files import serve, write_station

STATION = "st1"
#: the contract DBC's ranges: the drawn programs' limits are held inside them
MAX_TORQUE_NM = 8000.0
MAX_ANGLE_DEG = 80_000.0


@dataclass(frozen=True)
class LiveRun:
    run_id: int
    reached_n: float
    reached_torque_nm: float
    stopped_by: str  # the rig's stop source: stop_command, shutoff_force, limit_...
    decision: StopDecision | None


def program_text(number: int, joint: Joint, torque_only: bool, final_share: float | None) -> str:
    program = joint.program
    target = (
        f"target_torque_nm = {joint.target_torque_nm!r}"
        if torque_only
        else f"target_force_n = {joint.target_force_n!r}"
    )
    return f"""
[[programs]]
id = {number}
name = "joint {number}"
{target}
motor_speed_rad_s = {program.motor_speed_rad_s!r}
start_force_n = {program.start_force_n!r}
max_torque_nm = {MAX_TORQUE_NM}
max_force_n = {program.max_force_n!r}
max_angle_deg = {MAX_ANGLE_DEG}
max_time_s = {program.max_time_s!r}
joint = "joints/joint{number}.toml"
""" + (
        ""
        if final_share is None
        else f"""
[programs.final_stage]
speed_rad_s = {final_share * program.motor_speed_rad_s!r}
"""
    )


def write_files(
    folder: Path,
    joints: list[Joint],
    placement: str,
    torque_only: bool,
    final_share: float | None = None,
) -> Path:
    """The station file with one program (and one joint file) per joint."""
    (folder / "joints").mkdir(parents=True)
    for number, joint in enumerate(joints, 1):
        (folder / "joints" / f"joint{number}.toml").write_text(joint_toml(joint.constants))
    station = write_station(
        folder,
        placement=placement,
        replacements={"pause_between_runs_s = 0.3": "pause_between_runs_s = 0.05"},
    )
    text = station.read_text()
    programs = text[text.index("[[programs]]") : text.index("[predictor]")]
    body = "".join(program_text(n, j, torque_only, final_share) for n, j in enumerate(joints, 1))
    text = text.replace(programs, body + "\n")
    if torque_only:
        text = text.replace("has_force_sensor = true", "has_force_sensor = false")
    station.write_text(text)
    return station


def tighten_live(
    station_file: Path, joints: list[Joint], heard: Listener, folder: Path, torque_only: bool
) -> list[LiveRun]:
    """Every joint once through the real rig code on the station's bus."""
    station = load_station(station_file)
    frames = RigFrames(StationDatabase(station.dbc_path))
    use_realtime_priority(RIG_PRIORITY, "benchmark rig")
    first_run_id = int(time.time())
    out = []
    with open_bus(station.config.can) as bus:
        for number, joint in enumerate(joints, 1):
            tool = ToolIdentity(station.config.station.tool_id, not torque_only)
            rig = RealtimeRig(bus, frames, joint.constants, RigSection(), tool)
            program = station.config.program(number)
            summary = rig.run_one(program, first_run_id + number, joint.seed, threading.Event())
            out.append(
                LiveRun(
                    first_run_id + number,
                    summary.final_force_n,
                    summary.final_torque_nm,
                    str(summary.stop_source),
                    None,
                )
            )
            time.sleep(0.05)
    time.sleep(2.0)  # the last decisions and summaries on their way
    decisions = {d.run_id: d for d in reversed(heard.of(channels.DECISION.topic))}  # the first
    return [replace(r, decision=decisions.get(r.run_id)) for r in out]


def offline(
    live: LiveRun,
    joint: Joint,
    number: int,
    recordings: Path,
    station_file: Path,
    folder: Path,
    torque_only: bool,
) -> tuple[float, float, tuple[str, float] | None]:
    """(reached force, torque, (reason, time_s) decided) of the recorded run replayed."""
    (mcap,) = recordings.rglob(f"st1_run{live.run_id}_*.mcap")
    trace_file = folder / f"run{live.run_id}.csv"
    export_trace(mcap, trace_file, live.run_id)
    station = load_station(station_file)
    program = station.config.program(number)
    settings = PredictorSettings.of(
        program,
        station.config.predictor,
        station.config.station.has_force_sensor,
        JointConstants.of(station.joint_of(number)),
        station.sensor_range,
    )
    core = PredictorCore(settings)
    decided = next(
        ((str(o.reason), float(o.time_s)) for o in replay(core, read_trace(trace_file))
         if isinstance(o, CoreDecision)),
        None,
    )  # fmt: skip
    # the same joint again (same seed), halted at the sample that decided offline, or at
    # the tool's own shutoff at the target if that comes first: as the live rig halts
    at_sample = -1 if decided is None else round(decided[1] * 1000.0)
    sim = physics(joint)
    for index in range(max_samples(joint)):
        m = sim.advance()
        value, target = (
            (m.torque_nm, joint.target_torque_nm)
            if torque_only
            else (m.force_n, joint.target_force_n)
        )
        if index == at_sample or value >= target:
            break
    reached_n, reached_torque_nm = finish(sim)
    return reached_n, reached_torque_nm, decided


def staged_offline(program: Program, joint: Joint, torque_only: bool) -> StagedEnd:
    """The joint staged offline with the station's program: the rig's controller and the
    core, on the rig the live runs had (its defaults), obeying each command within the
    deciding sample's period as the live rig does (the core assumes a reaction of one
    sample, the station's default)."""
    return run_staged(
        joint.constants,
        program,
        RigSection(),
        joint.seed,
        torque_only,
        latency_samples=0,
        reaction_samples=1.0,
    )


def report(rows: dict[str, list[float]], title: str, oracle_name: str) -> None:
    print(f"\n{title}")
    print(f"{'policy':24s} {'mean%':>7s} {'median%':>7s} {'p95%':>7s}  /oracle   /conv")
    oracle_mean = statistics.fmean(rows[oracle_name])
    conv = next(v for k, v in rows.items() if k.startswith("conventional"))
    for name, values in rows.items():
        mean = statistics.fmean(values)
        print(
            f"{name:24s} {stats(values)}  {mean / oracle_mean:6.2f}  "
            f"{mean / statistics.fmean(conv):6.2f}"
        )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--joints", type=int, default=100)
    parser.add_argument("--seed", type=int, default=2018)
    parser.add_argument("--placement", choices=("edge", "line"), default="edge")
    parser.add_argument("--torque-only", action="store_true")
    parser.add_argument(
        "--final-share",
        type=float,
        default=None,
        help="each program gets a final stage at this share of its speed (a staged station: "
        "the live runs are compared with the same joints staged offline)",
    )
    parser.add_argument("--keep", type=Path, default=None, help="keep files and logs here")
    args = parser.parse_args(argv)
    if not 1 <= args.joints <= 255:
        raise SystemExit("--joints: 1 to 255 (one program per joint, ProgramId is 8 bits)")
    rng = np.random.default_rng(args.seed)
    joints = [draw_joint(rng, args.seed * 1000 + i) for i in range(args.joints)]
    with contextlib.ExitStack() as stack:
        if args.keep is not None:
            args.keep.mkdir(parents=True, exist_ok=True)
            folder = args.keep
        else:
            folder = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="bench-live-")))
        return measure(args, joints, folder)


def measure(args: argparse.Namespace, joints: list[Joint], folder: Path) -> int:
    station_file = write_files(folder, joints, args.placement, args.torque_only, args.final_share)
    station = load_station(station_file)
    endpoint = station.config.zenoh.connect[0]
    processes = [serve(["router", "--listen", endpoint], folder / "router.log", REPO)]
    started = time.monotonic()
    try:
        names = ["recorder", "acquisition"] + (["predictor"] if args.placement == "line" else [])
        for name in names:
            extra = ["--no-rerun"] if name == "recorder" else []
            arguments = [name, "--config", str(station_file), *extra]
            processes.append(serve(arguments, folder / f"{name}.log", REPO))
        with (
            zenoh.open(zenoh_config("client", [endpoint])) as session,
            Listener(session, STATION, (channels.DECISION.topic,)) as heard,
        ):
            wait_alive(session, STATION, [folder])
            live_runs = tighten_live(station_file, joints, heard, folder, args.torque_only)
    finally:
        for process in reversed(processes):
            stop_process(process, grace_s=10.0)
    live_s = time.monotonic() - started
    rows: dict[str, list[float]] = {"oracle": [], "conventional": [], "live": [], "offline": []}
    torque_rows: dict[str, list[float]] = {k: [] for k in rows}
    same = compared = 0
    stopped_by: Counter[str] = Counter()
    for number, (joint, live) in enumerate(zip(joints, live_runs, strict=True), 1):
        best = oracle(joint)
        conv = conventional(joint, args.torque_only)
        reached, reached_torque, decided = offline(
            live, joint, number, station.recordings_folder, station_file, folder, args.torque_only
        )
        stopped_by[live.stopped_by] += 1
        if live.decision is not None and decided is not None:
            compared += 1
            same += decided[0] == live.decision.reason and math.isclose(
                decided[1], live.decision.time_s, abs_tol=1e-9
            )
        for name, force, torque in (
            ("oracle", best.reached_n, best.reached_torque_nm),
            ("conventional", conv.reached_n, conv.reached_torque_nm),
            ("live", live.reached_n, live.reached_torque_nm),
            ("offline", reached, reached_torque),
        ):
            rows[name].append(error(joint, force))
            torque_rows[name].append(torque_error(joint, torque))
    mode = "torque-only" if args.torque_only else "force"
    if args.final_share is not None:
        mode += f", a final stage at {args.final_share:g} of the speed"
        staged = [
            staged_offline(station.config.program(n), joint, args.torque_only)
            for n, joint in enumerate(joints, 1)
        ]
        rows["offline staged"] = [
            error(j, end.force_n) for j, end in zip(joints, staged, strict=True)
        ]
        torque_rows["offline staged"] = [
            torque_error(j, end.torque_nm) for j, end in zip(joints, staged, strict=True)
        ]
        pulsed = sum(end.pulses > 0 for end in staged)
        print(f"offline staged: {pulsed} of {len(staged)} runs took a pulse")
    print(
        f"{len(joints)} joints, {mode}, placement {args.placement}, live through the real "
        f"processes in {live_s:.0f} s"
    )
    print(f"live = offline: {same} of {compared} decisions (same reason, same sample)")
    print(f"what stopped the tool: {dict(stopped_by)}")
    report(rows, "|F_reached - F_target| / F_target", "oracle")
    if args.torque_only:
        report(torque_rows, "|T_reached - T_target| / T_target (settled torque)", "oracle")
    return 0


if __name__ == "__main__":
    sys.exit(main())
