"""Synthetic edge stations that publish as the acquisition does, for the recording stress.

A child process of ``bench_recording_stress.py`` (``python -m
tests.benchmarks.stress_stations MANIFEST FILES...``). Each station of its
station files gets what a real acquisition on the edge gets: its own zenoh
session opened from its ``[zenoh]`` section (a peer that reaches its router
in the background when it spools, as :func:`shared.runtime.open_session` does
for a spooling service), and a :class:`~shared.runtime.queued_publisher.QueuedPublisher`
with ``batch_samples=True`` (``--per-sample`` station ids: False, each sample
put alone, as a station whose predictor is on the line does) and its spool (or
none: ``--no-spool`` station ids), to which it hands :class:`Sample` objects one by one, a
:class:`StickSlipEvent` and its :class:`Intensity` every 25 samples (they ride
in the batch in progress), ``ToolState`` running and done around each run and
:class:`BusStats` with the count of samples published. Only the CAN bus and
the predictor are left out: what reaches zenoh is what an acquisition puts.

The stations publish side by side, sample by sample, at ``--rate`` samples a
second in all (not 1 kHz each: 50 stations of real acquisitions do not fit on
two cores; 0: as fast as the machine lets them), and each waits for its
publisher's thread to catch up every :data:`CATCH_UP_SAMPLES` samples
(:meth:`QueuedPublisher.call`), so its queue never nears its bound and no sample
is dropped for want of room. At the end every spool is drained (the recorder
has acknowledged all it holds) before the process exits, and the manifest
(JSON) says, per station, each run's id and sample count and whether it spooled
(``MANIFEST`` with the suffix ``.published`` is written once every run is
handed to the publishers, before the drain).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import signal
import sys
import threading
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from shared.config import LoadedStation, load_station
from shared.contract import BusStats, Intensity, Sample, StickSlipEvent, ToolState
from shared.runtime import open_session
from shared.runtime.queued_publisher import QueuedPublisher, station_spool
from tests.support.fuzz.payloads import template
from tests.support.synthetic_runs import staircase

#: a station waits for its publisher's thread at most this many samples behind
CATCH_UP_SAMPLES = 2_000
EVENT_EVERY_SAMPLES = 25
#: the pace is kept every this many samples of each station
PACE_SAMPLES = 50
DRAIN_TIMEOUT_S = 600.0


def run_rows(samples: int) -> list[tuple[float, float, float]]:
    """(torque, angle, force) of each sample of a run: a stick-slip staircase."""
    trace = staircase(torque_noise_nm=0.2, force_noise_n=30.0, duration_s=samples / 1e3 + 0.01)
    return [(torque, angle, force) for _t, torque, force, angle in trace.rows()][:samples]


class StressStation:
    """One station's session, publisher and counts."""

    def __init__(
        self, loaded: LoadedStation, spool: bool, batches: bool, first_run_id: int
    ) -> None:
        self.station = loaded.station_id
        self.tool_id = loaded.config.station.tool_id
        spooled = station_spool(loaded, "acquisition") if spool else None
        self.session = open_session(loaded.config.zenoh, wait_for_router=spooled is None)
        self.publisher = QueuedPublisher(
            self.session, self.station, batch_samples=batches, spool=spooled
        )
        self.runs: dict[int, int] = {}
        self.next_run_id = first_run_id
        self.published = 0
        self.started_ns = time.time_ns()
        self._caught_up = threading.Event()
        self._caught_up.set()
        now_ns = time.time_ns()
        self._event: StickSlipEvent = template("events", self.station, now_ns, first_run_id)
        self._intensity: Intensity = template("intensity", self.station, now_ns, first_run_id)

    def start_run(self) -> int:
        """Tool running: a new run; its id."""
        run_id = self.next_run_id
        self.next_run_id += 1
        self.publisher.publish(
            ToolState(self.station, run_id, self.tool_id, 1, "running", time.time_ns())
        )
        return run_id

    def sample(self, run_id: int, sequence: int, row: tuple[float, float, float]) -> None:
        """One sample of the run; an event and its intensity every 25 (in its batch)."""
        publish = self.publisher.publish
        now_ns = time.time_ns()
        torque, angle, force = row
        time_s = sequence / 1e3
        publish(Sample(self.station, run_id, sequence, now_ns, torque, angle, force, time_s))
        if sequence % EVENT_EVERY_SAMPLES == EVENT_EVERY_SAMPLES - 1:
            publish(dataclasses.replace(self._event, run_id=run_id, time_ns=now_ns))
            publish(dataclasses.replace(self._intensity, run_id=run_id, time_ns=now_ns))
        if sequence % CATCH_UP_SAMPLES == CATCH_UP_SAMPLES - 1:
            self.catch_up()

    def end_run(self, run_id: int, samples: int) -> None:
        """Tool done, and the bus counters with the run's samples."""
        self.published += samples
        self.runs[run_id] = samples
        self.publisher.publish(
            ToolState(self.station, run_id, self.tool_id, 1, "done", time.time_ns())
        )
        self.bus()

    def catch_up(self) -> None:
        """Wait until the publisher's thread has put what was handed to it before the last
        call (one call in flight: the thread always has work)."""
        self._caught_up.wait()
        self._caught_up.clear()
        self.publisher.call(self._caught_up.set)

    def bus(self) -> None:
        stats = BusStats(
            self.station, time.time_ns(), 0, self.published, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0
        )
        self.publisher.publish(dataclasses.replace(stats, started_ns=self.started_ns))

    def spool_depth(self) -> int | None:
        """Messages the spool still holds (None: no spool), asked on the publisher's thread."""
        spool = self.publisher._spool  # the benchmark's own look at its drain
        if spool is None:
            return None
        answer: list[int] = []
        done = threading.Event()

        def ask() -> None:
            answer.append(spool.stats().messages)
            done.set()

        self.publisher.call(ask)
        done.wait(30.0)
        return answer[0] if answer else -1

    def close(self) -> dict[str, Any]:
        self.publisher.close()
        self.session.close()
        return {
            "spool": self.publisher.spooling,
            "batches": self.publisher._batching is not None,
            "runs": {str(run_id): count for run_id, count in self.runs.items()},
            "published": self.published,
            "dropped": self.publisher.dropped,
            "failed": self.publisher.failed,
            "lost": self.publisher.lost_samples,
            "spool_errors": self.publisher.spool_errors,
        }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("manifest", type=Path)
    parser.add_argument("files", nargs="+", type=Path)
    parser.add_argument("--runs", type=int, required=True, help="runs per station")
    parser.add_argument("--run-samples", type=int, default=1000)
    parser.add_argument(
        "--rate", type=float, default=0.0, help="samples a second, all its stations (0: at once)"
    )
    parser.add_argument("--no-spool", nargs="*", default=[], help="station ids without spool")
    parser.add_argument(
        "--per-sample", nargs="*", default=[], help="station ids that put each sample alone"
    )
    args = parser.parse_args(argv)
    stopped = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stopped.set())
    rows = run_rows(args.run_samples)
    first_run_id = int(time.time()) * 1000
    stations = []
    for path in args.files:
        loaded = load_station(path)
        station_id = loaded.station_id
        spool, batches = station_id not in args.no_spool, station_id not in args.per_sample
        stations.append(StressStation(loaded, spool, batches, first_run_id))
    time.sleep(2.0)  # the router learns the subscribers
    started = time.monotonic()
    per_s = args.rate / len(stations) if args.rate else 0.0  # samples a second, each station
    for _ in range(args.runs):
        if stopped.is_set():
            break
        run_ids = [station.start_run() for station in stations]
        run_started = time.monotonic()
        for sequence, row in enumerate(rows):  # the stations side by side, sample by sample
            for station, run_id in zip(stations, run_ids, strict=True):
                station.sample(run_id, sequence, row)
            if per_s and sequence % PACE_SAMPLES == 0:
                time.sleep(max(0.0, run_started + sequence / per_s - time.monotonic()))
        for station, run_id in zip(stations, run_ids, strict=True):
            station.end_run(run_id, len(rows))
    published_s = time.monotonic() - started
    args.manifest.with_suffix(".published").write_text(f"{published_s:.1f}\n")
    deadline = time.monotonic() + DRAIN_TIMEOUT_S
    depths = [station.spool_depth() for station in stations]
    while any(d for d in depths) and time.monotonic() < deadline and not stopped.is_set():
        time.sleep(1.0)
        depths = [station.spool_depth() for station in stations]
    drained_s = time.monotonic() - started
    manifest = {station.station: station.close() for station in stations}
    args.manifest.write_text(json.dumps(manifest))
    samples = sum(int(m["published"]) for m in manifest.values())
    print(
        f"stress stations: {samples} samples in {published_s:.1f} s, spools drained at "
        f"{drained_s:.1f} s (left: {[d for d in depths if d]})",
        flush=True,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
