"""Store and forward, measured: what a station's spool needs, how fast it drains, and zenoh's
own cache beside it (not a test).

Run on demand::

    .venv/bin/python tests/benchmarks/bench_spool.py [--runs 20] [--stations 10]
        [--skip-station]

1. **A station's hour.** The real processes (``serve acquisition`` with its edge
   predictor, ``serve rig``) tighten ``--runs`` joints on loopback with no
   recorder on the line: nothing is acknowledged, the spool keeps everything.
   Reported: spool bytes and messages per run, runs per hour at the rig's
   pace, and so bytes per station-hour (the default ``[spool] max_bytes``
   must hold 8 hours).
2. **A cut of 10 minutes and of an hour.** What a spool holds after a
   10-minute cut (step 1's messages, repeated with fresh numbers: time
   compressed) drained into a live recorder through real zenoh at
   ``--rate`` (the default ``drain_messages_per_s``) and at 2000/s:
   messages per second and the time to empty; an hour's cut is six times
   that (the rate is the bound, not the recorder).
3. **A line coming back at once.** ``--stations`` spools, each holding a
   10-minute cut, drained at once at ``--rate`` into a recorder process
   (``serve recorder --no-rerun``, as a line's server runs it) while a real
   station (``serve acquisition``, ``serve rig``) tightens live: that
   station's recorder lag (its RecorderStats' ``lag_p50_ms`` and
   ``lag_max_ms``) for 20 s before the drain and during
   it, side by side, and the time until every spool is empty.
4. **zenoh's AdvancedPublisher cache** (zenoh-ext, the alternative looked at
   first): the process's resident memory for a cache holding step 1's
   messages scaled to an hour (measured on 10 minutes), and whether a
   late-joining AdvancedSubscriber gets the history (it does, from a running
   publisher) and whether anything survives the publisher's restart (nothing:
   the cache is the publisher's memory).

The stop path while the station spools is ``bench_stop_path.py`` (the spool
is on by default), side by side with the code before with ``--repo``.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

import zenoh
import zenoh.ext

from services.cli.station_supervisor import stop_process
from shared.config import load_station
from shared.contract import RecorderStats, SpoolStats
from shared.runtime import QueuedPublisher, zenoh_config
from shared.spool import SeqRanges, Spooled, SpoolFile, StationSpool
from tests.support.listener import Listener
from tests.support.live_recorder import RunningRecorder, free_port, write_station_file
from tests.support.station_files import serve, write_station

HOUR_S = 3600.0


def station_hour(folder: Path, runs: int) -> tuple[list[Spooled], float]:
    """Step 1: the spooled messages of ``runs`` real runs and the seconds they took."""
    path = write_station(folder, zenoh_mode="peer")
    station = load_station(path)
    logs = folder / "logs"
    logs.mkdir()
    acquisition = serve(["acquisition", "--config", str(path)], logs / "acquisition.log")
    try:
        time.sleep(3.0)
        started = time.monotonic()
        rig = serve(["rig", "--config", str(path), "--runs", str(runs)], logs / "rig.log")
        assert rig.wait(runs * 20) == 0, f"the rig failed: {logs}"
        took_s = time.monotonic() - started
        time.sleep(1.5)  # the last group commit and stats
    finally:
        stop_process(acquisition)
    spool = SpoolFile(station.spool_folder / f"{station.station_id}-acquisition.sqlite")
    messages = spool.after(0, 10**9, 2**62, SeqRanges())
    depth = spool.depth()
    spool.close()
    per_run = depth.file_bytes / runs
    runs_per_hour = runs / took_s * HOUR_S
    print(
        f"1. a station's hour: {runs} runs in {took_s:.1f} s, {depth.messages} messages, "
        f"{depth.samples} samples, spool {depth.file_bytes / 1e6:.2f} MB on disk "
        f"({per_run / 1e3:.1f} kB a run, {len(messages) / runs:.0f} messages a run); "
        f"{runs_per_hour:.0f} runs an hour: {per_run * runs_per_hour / 1e6:.0f} MB "
        f"per station-hour, {8 * per_run * runs_per_hour / 1e9:.2f} GB for 8 hours"
    )
    return messages, took_s


def cut_spool(path: Path, station: str, messages: list[Spooled], repeat: int) -> StationSpool:
    """A spool holding ``messages`` ``repeat`` times over (fresh numbers), of ``station``."""
    spool = SpoolFile(path)
    for _ in range(repeat):
        for message in messages:
            payload = message.payload.replace(b'"station":"st1"', f'"station":"{station}"'.encode())
            spool.append(message.topic, payload, 0, None, 0, time.time_ns() - 10**12)
        spool.commit()
    return StationSpool(station, "acquisition", spool, 1 << 40, 200.0, 1.0)


def spools_empty(heard: Listener, stations: list[str]) -> bool:
    """Every station's latest SpoolStats: nothing waits, and something was sent again."""
    latest: dict[str, SpoolStats] = {stats.station: stats for stats in heard.of("spool")}
    return all(s in latest and latest[s].messages == 0 and latest[s].resent > 0 for s in stations)


def drain(
    folder: Path, messages: list[Spooled], cut_s: float, took_s: float, rate: float
) -> tuple[float, int]:
    """Step 2: one station's spool holding ``cut_s`` of step 1, drained into a recorder (in
    this process) at ``rate``; (seconds to empty, messages)."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    path = write_station_file(folder / "st1.toml", folder / "recordings", listen=[endpoint])
    recorder = RunningRecorder(load_station(path))
    session = zenoh.open(zenoh_config("peer", connect=[endpoint]))
    heard = Listener(session, "*", topics=["spool"])
    spool = cut_spool(folder / "edge.sqlite", "st1", messages, max(1, round(cut_s / took_s)))
    spool._rate = rate  # the benchmark's rate (the station file's drain_messages_per_s)
    total = spool.stats().messages
    started = time.monotonic()
    publisher = QueuedPublisher(session, "st1", True, spool=spool)
    try:
        while not spools_empty(heard, ["st1"]):
            time.sleep(0.2)
        return time.monotonic() - started, total
    finally:
        publisher.close()
        recorder.finish()
        heard.close()
        session.close()


def line_drain(
    folder: Path, messages: list[Spooled], took_s: float, stations: int, rate: float
) -> tuple[float, int, list[RecorderStats], list[RecorderStats]]:
    """Step 3: ``stations`` spools of a 10-minute cut each drained at once into a recorder
    process (``serve recorder``), while a real station (``serve acquisition`` and ``serve
    rig``) tightens live; (seconds to empty, messages, the live station's RecorderStats
    before the drain, during it)."""
    port = free_port()
    endpoint = f"tcp/127.0.0.1:{port}"
    (folder / "live").mkdir()
    live = write_station(folder / "live", zenoh_port=port)  # a client of the line's router
    names = [f"d{n}" for n in range(1, stations + 1)]
    files = []
    for name in names:  # the same file but its id: one recorder serves files that agree
        path = folder / f"{name}.toml"
        path.write_text(live.read_text().replace('id = "st1"', f'id = "{name}"'))
        files.append(str(path))
    logs = folder / "logs"
    logs.mkdir()
    processes = [serve(["router", "--listen", endpoint], logs / "router.log")]
    time.sleep(2.0)
    recorder = ["recorder", "--no-rerun", "--config", *files, str(live)]  # a line's server
    processes.append(serve(recorder, logs / "recorder.log"))
    time.sleep(3.0)
    processes.append(serve(["acquisition", "--config", str(live)], logs / "acquisition.log"))
    processes.append(serve(["rig", "--config", str(live)], logs / "rig.log"))
    session = zenoh.open(zenoh_config("peer", connect=[endpoint]))
    heard = Listener(session, "*", topics=["spool", "recorder"])
    repeat = max(1, round(600.0 / took_s))
    spools = [cut_spool(folder / f"{name}.sqlite", name, messages, repeat) for name in names]
    for spool in spools:
        spool._rate = rate
    total = sum(spool.stats().messages for spool in spools)
    publishers = []
    try:
        time.sleep(20.0)  # the live station alone: the lag before
        before = len(heard.of("recorder"))
        started = time.monotonic()
        publishers = [QueuedPublisher(session, s.station, True, spool=s) for s in spools]
        while not spools_empty(heard, names):
            time.sleep(0.2)
        took = time.monotonic() - started
        during = len(heard.of("recorder"))
    finally:
        for publisher in publishers:
            publisher.close()
        for process in reversed(processes):
            stop_process(process)
        heard.close()
        session.close()
    every = heard.of("recorder")
    alone = [s for s in every[:before] if s.station == "st1" and s.lag_p50_ms is not None]
    draining = [s for s in every[before:during] if s.station == "st1" and s.lag_p50_ms is not None]
    return took, total, alone, draining


def drain_line(folder: Path, messages: list[Spooled], took_s: float, rate: float) -> str:
    """Step 2 at ``rate``, in one line."""
    folder.mkdir()
    seconds, total = drain(folder, messages, 600.0, took_s, rate)
    return (
        f"2. a 10-minute cut, drained at {rate:.0f}/s: {total} messages in {seconds:.1f} s "
        f"({total / seconds:.0f} messages/s; an hour's cut: {6 * seconds / 60:.1f} min)"
    )


def line_line(
    folder: Path, messages: list[Spooled], took_s: float, stations: int, rate: float
) -> str:
    """Step 3, in one line."""
    folder.mkdir()
    seconds, total, alone, draining = line_drain(folder, messages, took_s, stations, rate)
    return (
        f"3. {stations} stations, a 10-minute cut each, drained at once at {rate:.0f}/s "
        f"each: {total} messages in {seconds:.1f} s; a live station's recorder lag alone: "
        f"{lag_text(alone)}; while they drain: {lag_text(draining)}"
    )


def lag_text(stats: list[RecorderStats]) -> str:
    lags = [s.lag_p50_ms for s in stats if s.lag_p50_ms is not None]
    peaks = [s.lag_max_ms for s in stats if s.lag_max_ms is not None]
    if not lags:
        return "no lag heard"
    return (
        f"p50 {statistics.median(lags):.1f} ms (median of {len(lags)} s), max {max(peaks):.1f} ms"
    )


def resident_kb() -> int:
    """This process's resident memory now (VmRSS), in kB."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    return 0


def advanced_publisher(messages: list[Spooled], scale: int) -> None:
    """Step 4: zenoh-ext's cache, in this process's memory."""
    session = zenoh.open(zenoh_config("peer"))
    before_kb = resident_kb()
    count = len(messages) * scale
    publishers: dict[str, zenoh.ext.AdvancedPublisher] = {}
    for message in messages:
        if message.topic not in publishers:
            publishers[message.topic] = zenoh.ext.declare_advanced_publisher(
                session,
                f"boltwatch/st1/{message.topic}",
                cache=zenoh.ext.CacheConfig(max_samples=count),
                sample_miss_detection=zenoh.ext.MissDetectionConfig(
                    heartbeat=1.0, sporadic_heartbeat=None
                ),
                publisher_detection=True,
            )
    payload_bytes = 0
    for _ in range(scale):
        for message in messages:
            publishers[message.topic].put(message.payload)
            payload_bytes += len(message.payload)
    after_kb = resident_kb()
    got: list[int] = []
    subscriber = zenoh.ext.declare_advanced_subscriber(
        session,
        "boltwatch/st1/tool",
        lambda sample: got.append(1),
        history=zenoh.ext.HistoryConfig(detect_late_publishers=True),
        recovery=zenoh.ext.RecoveryConfig(periodic_queries=None, heartbeat=True),
    )
    time.sleep(2.0)
    tool_puts = sum(1 for m in messages if m.topic == "tool") * scale
    for publisher in publishers.values():
        publisher.undeclare()
    subscriber.undeclare()
    session.close()
    print(
        f"4. AdvancedPublisher cache: {count} messages ({payload_bytes / 1e6:.0f} MB of "
        f"payloads) took {(after_kb - before_kb) / 1e3:.0f} MB more of this process's memory "
        f"(in RAM, uncompressed, per key max_samples); a late-joining AdvancedSubscriber got "
        f"{len(got)} of {tool_puts} tool states from the running publisher's cache; "
        "a restarted publisher starts with an empty cache (nothing on disk)"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=20, help="real runs measured (20)")
    parser.add_argument("--stations", type=int, default=10, help="stations draining at once")
    parser.add_argument(
        "--rate", type=float, default=100.0, help="drain_messages_per_s (the default, 100)"
    )
    parser.add_argument("--keep", type=Path, default=None, help="keep files here")
    parser.add_argument(
        "--steps", default="1234", help="which steps (1 always: the others use its messages)"
    )
    args = parser.parse_args()
    with contextlib.ExitStack() as stack:
        folder = args.keep or Path(stack.enter_context(tempfile.TemporaryDirectory()))
        (folder / "station").mkdir(parents=True, exist_ok=True)
        messages, took_s = station_hour(folder / "station", args.runs)
        if "2" in args.steps:
            for rate in (args.rate, 2000.0):
                print(drain_line(folder / f"drain-{rate:.0f}", messages, took_s, rate))
        if "3" in args.steps:
            print(line_line(folder / "line", messages, took_s, args.stations, args.rate))
        if "4" in args.steps:
            advanced_publisher(messages, max(1, round(600.0 / took_s)))
        print(json.dumps({"runs": args.runs, "run_s": took_s / args.runs}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
