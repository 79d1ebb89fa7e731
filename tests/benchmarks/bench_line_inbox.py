"""The predictor process's CPU per sample on a line, for several ways of receiving from zenoh.

Run on demand (not collected by pytest)::

    .venv/bin/python tests/benchmarks/bench_line_inbox.py --stations 20 --seconds 8 --rounds 2

Per round and variant: one router, one predictor process (the real
:class:`PredictorService` over N station files, only its inbox differs) and
the load generator of ``bench_line.py`` (N synthetic stations at 1 kHz, 1 s
runs). Measured: the predictor's user + system CPU (``/proc/<pid>/stat``)
while the generator runs, divided by the samples it published, and whether
every synthetic run was summarised with all its samples (kept up), and the
median lag of those summaries (received minus the run's ``done``). The
variants run in turns within one round, so a busy machine hurts them alike.

- ``callback``: :class:`StationInbox`, the service's own: each subscriber's
  callback runs on zenoh's receive thread and handles the message there.
- ``fifo-threads``: one ``FifoChannel`` subscriber per station and topic,
  one thread each blocking in ``recv()``, handling under one lock.
- ``callback-unpinned``: ``callback`` without keeping the receive threads'
  Python thread states (CPython makes and frees one per callback).
- ``callback-rx1``: ``callback`` with zenoh's receive pool at one thread
  (``ZENOH_RUNTIME``), so callbacks never pass the GIL between two threads.
- ``recorder``: the real recorder process (``--no-rerun``) instead of the
  predictor; "runs" are not its output, the samples in its MCAP files are
  (``recorded``, printed beside ``published``: compare them).
- ``recorder-at-before``: ``serve recorder --no-rerun`` of another checkout
  (``--before-repo``, e.g. ``git worktree add /tmp/before c7ff33d``), run
  side by side with the current one.
- ``indirect``: like ``callback`` with ``indirect=True`` (zenoh runs each
  subscriber's callbacks on a thread of its own).

The figures for the former inbox (one ``queue.Queue`` and a worker thread)
and for the recorder's ``classify`` as it was (in CHANGELOG.md) were taken
with copies of that code, since removed: compare with another checkout
(``recorder-at-before``) instead.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import zenoh

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from services.cli.station_supervisor import stop_process
from services.predictor.service import PredictorService
from services.predictor.station_inbox import Handler, Inbox, StationInbox
from shared.config import derive_stations, load_line
from shared.contract import (
    RunSummary,
    channels,
    decode,
    keys,
)
from shared.recordings.mcap import RecordingScan
from shared.runtime import (
    ServiceSkeleton,
    zenoh_config,
)
from tests.benchmarks.bench_line import cpu_s, wait_alive
from tests.benchmarks.line_station_runs import SHORT_PROGRAM
from tests.support.station_files import free_tcp_port, serve, write_station
from tests.support.synthetic_runs import staircase

TOPICS = (channels.SAMPLES.topic, channels.TOOL.topic)
WAKE = b""


class FifoThreadsInbox:
    """One FifoChannel subscriber per station and topic, one thread each in ``recv()``."""

    def __init__(self, session: zenoh.Session, station_ids: Sequence[str], handle: Handler):
        self._session = session
        self._handle = handle
        self._lock = threading.Lock()
        self._keys = [(s, t) for s in station_ids for t in TOPICS]
        self._subscribers = [
            session.declare_subscriber(keys.station_key(s, t), zenoh.handlers.FifoChannel(1000))
            for s, t in self._keys
        ]

    def serve(self, stop: threading.Event) -> None:
        threads = [
            threading.Thread(target=self._receive, args=(sub, s, t, stop), daemon=True)
            for sub, (s, t) in zip(self._subscribers, self._keys, strict=True)
        ]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()

    def _receive(
        self, subscriber: zenoh.Subscriber, station_id: str, topic: str, stop: threading.Event
    ) -> None:
        while not stop.is_set():
            payload = subscriber.recv().payload.to_bytes()
            if payload != WAKE:
                with self._lock:
                    self._handle(station_id, topic, payload)

    def wake(self) -> None:
        for s, t in self._keys:
            self._session.put(
                keys.station_key(s, t), WAKE, allowed_destination=zenoh.Locality.SESSION_LOCAL
            )

    def close(self) -> None:
        for subscriber in self._subscribers:
            subscriber.undeclare()


class IndirectInbox(StationInbox):
    """:class:`StationInbox` with zenoh's ``indirect=True`` (a thread per subscriber)."""

    def __init__(self, session: zenoh.Session, station_ids: Sequence[str], handle: Handler):
        super().__init__(session, [], handle)
        self._subscribers = [
            session.declare_subscriber(
                keys.station_key(s, t),
                zenoh.handlers.Callback(self._deliver_to(s, t), indirect=True),
            )
            for s in station_ids
            for t in TOPICS
        ]


class UnpinnedInbox(StationInbox):
    """:class:`StationInbox` letting CPython make a thread state per callback."""

    keep_thread_states = False


VARIANTS: dict[str, Callable[[zenoh.Session, Sequence[str], Handler], Inbox]] = {
    "callback": StationInbox,
    "callback-unpinned": UnpinnedInbox,
    "callback-rx1": StationInbox,
    "fifo-threads": FifoThreadsInbox,
    "indirect": IndirectInbox,
}
#: variant -> ZENOH_RUNTIME (zenoh's runtime pools, RON) of its predictor process
RUNTIMES = {"callback-rx1": "(rx: (worker_threads: 1))"}


#: recorder variants: the real ``serve recorder --no-rerun`` of this checkout or of another
RECORDER_VARIANTS = ("recorder", "recorder-at-before")


def consumer_command(variant: str, paths: list[Path], before_repo: Path | None) -> list[str]:
    """The process of one variant: this file as a child, or the other checkout's recorder."""
    if variant != "recorder-at-before":
        return [sys.executable, __file__, "--consume", variant, *map(str, paths)]
    if before_repo is None:
        raise SystemExit("recorder-at-before needs --before-repo PATH")
    serve_recorder = ["-m", "services.cli", "serve", "recorder", "--no-rerun", "--config"]
    return [sys.executable, *serve_recorder, *map(str, paths)]


def recorded_samples(recordings: Path) -> int:
    """Sample messages in every MCAP file under ``recordings``."""
    suffix = f"/{channels.SAMPLES.topic}"
    return sum(
        sum(1 for _ in RecordingScan(path).messages(suffix))
        for path in sorted(recordings.rglob("*.mcap"))
    )


def consume(variant: str, files: list[str]) -> int:
    """The process of one variant (a child: bench_line_inbox.py --consume ...)."""
    if variant in RECORDER_VARIANTS:
        from services.cli.main import main as boltwatch

        return boltwatch(["serve", "recorder", "--no-rerun", "--config", *files])
    if variant in RUNTIMES:  # read when zenoh's runtime starts: before the first session
        os.environ["ZENOH_RUNTIME"] = RUNTIMES[variant]
    stations = load_line([Path(f) for f in files])
    with ServiceSkeleton("predictor") as skeleton:
        skeleton.open_session(stations[0].config.zenoh)
        service = PredictorService(skeleton, stations, inbox=VARIANTS[variant])
        return skeleton.run(service.work, service.wake)


def one_run(
    variant: str, stations: int, seconds: float, folder: Path, before_repo: Path | None
) -> dict[str, float]:
    port = free_tcp_port()
    endpoint = f"tcp/127.0.0.1:{port}"
    base = write_station(folder, zenoh_port=port, replacements=SHORT_PROGRAM)
    paths = derive_stations(base, stations, folder / "stations")
    ids = [p.stem for p in paths]
    expected_samples = len(staircase(duration_s=1.0).rows())
    summaries: list[RunSummary] = []
    lag_ms: list[float] = []

    def on_summary(sample: zenoh.Sample) -> None:
        summary = decode(RunSummary, sample.payload.to_bytes())
        lag_ms.append((time.time_ns() - summary.ended_ns) / 1e6)
        summaries.append(summary)

    processes: list[subprocess.Popen[bytes]] = []
    try:
        processes.append(serve(["router", "--listen", endpoint], folder / "router.log"))
        predictor = subprocess.Popen(
            consumer_command(variant, paths, before_repo),
            cwd=before_repo if variant == "recorder-at-before" else REPO,
            stdout=(folder / "predictor.log").open("wb"),
            stderr=subprocess.STDOUT,
        )
        processes.append(predictor)
        with zenoh.open(zenoh_config("client", [endpoint])) as session:
            runs = session.declare_subscriber(
                channels.RUNS.key("*"),
                on_summary,
            )
            service = "recorder" if variant in RECORDER_VARIANTS else "predictor"
            wait_alive(session, {(s, service) for s in ids}, processes, folder)
            before = cpu_s(predictor)
            generator = subprocess.Popen(
                [
                    sys.executable,
                    str(REPO / "tests/benchmarks/bench_line.py"),
                    "--generate",
                    endpoint,
                    "--seconds",
                    str(seconds),
                    # a line predictor decides on each sample: its stations publish them alone
                    *([] if variant in RECORDER_VARIANTS else ["--per-sample"]),
                    *map(str, paths),
                ],
                cwd=REPO,
                stdout=(folder / "generator.log").open("wb"),
                stderr=subprocess.STDOUT,
            )
            generator.wait(timeout=seconds + 60.0)
            time.sleep(1.0)  # the last summaries
            used_s = cpu_s(predictor) - before
            runs.undeclare()
    finally:
        for process in reversed(processes):
            stop_process(process, grace_s=10.0)
    note = (folder / "generator.log").read_text()
    published = int(note.split("generator: ", 1)[1].split()[0])
    recorded = recorded_samples(folder / "recordings") if variant in RECORDER_VARIANTS else -1
    return {
        "recorded": recorded,
        "cpu_us_per_sample": used_s / published * 1e6,
        "runs": len(summaries),
        "incomplete_runs": sum(1 for s in summaries if s.samples != expected_samples),
        "published": published,
        "summary_lag_p50_ms": statistics.median(lag_ms) if lag_ms else math.nan,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--stations", type=int, default=20)
    parser.add_argument("--seconds", type=float, default=8.0)
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument(
        "--variants",
        nargs="+",
        default=list(VARIANTS),
        choices=[*VARIANTS, *RECORDER_VARIANTS],
        help="predictor inboxes (default: all) or the recorder, this checkout's or another's",
    )
    parser.add_argument(
        "--before-repo", type=Path, default=None, help="the checkout of recorder-at-before"
    )
    parser.add_argument("--consume", default=None, help=argparse.SUPPRESS)
    parser.add_argument("files", nargs="*", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.consume:
        return consume(args.consume, args.files)
    cpu: dict[str, list[float]] = {v: [] for v in args.variants}
    for round_index in range(args.rounds):
        order = args.variants if round_index % 2 == 0 else list(reversed(args.variants))
        for variant in order:
            with tempfile.TemporaryDirectory(prefix=f"bench-inbox-{variant}-") as tmp:
                result = one_run(variant, args.stations, args.seconds, Path(tmp), args.before_repo)
            cpu[variant].append(result["cpu_us_per_sample"])
            print(
                f"round {round_index + 1} {variant}: {result['cpu_us_per_sample']:.1f} µs/sample, "
                f"{result['runs']:.0f} runs, {result['incomplete_runs']:.0f} incomplete, "
                f"{result['published']:.0f} samples ({result['recorded']:.0f} recorded), "
                f"summary lag p50 {result['summary_lag_p50_ms']:.1f} ms",
                flush=True,
            )
    for variant, values in cpu.items():
        median = statistics.median(values)
        print(f"{variant}: median {median:.1f} µs CPU/sample ≈ {1e3 / median:.0f} stations/core")
    return 0


if __name__ == "__main__":
    sys.exit(main())
