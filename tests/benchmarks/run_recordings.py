"""Recordings of whole runs as the recorder writes them, for ``bench_results_store.py``'s file
scan and the traces of ``bench_opcua_publish.py``: the real :class:`Recorder` (MCAP, zstd,
no Rerun), fed classified messages on a simulated 1 kHz clock, without zenoh.

Each run is what a CAN station's line recorder files of it: its tool state
``running``, ``samples`` samples in batches of 50 (an edge station's
``SampleBatch``, 50 ms) whose torque, angle and preload rise with noise, at
the CAN signals' resolutions (so they compress as measured ones do, not as
constants), a stick-slip event and
its intensity every ``samples // 10`` samples, the stop decision, the tool
state ``done``, the run's summary and its ``TighteningResult``: one file a
run (``<station>_run<id>_<HHMMSS>.mcap``).
"""

from __future__ import annotations

import random
from pathlib import Path

from services.recorder.live.recorder import Recorder
from services.recorder.live.run_files import FileLimits
from shared.config import load_station
from shared.contract import Intensity, Sample, StopDecision, ToolState, encode
from shared.recordings import FileMetadata, classify
from tests.support import factories
from tests.support.live_recorder import write_station_file

MS = 1_000_000
BATCH = 50
EVENTS = 9
#: 2026-07-01 00:00 UTC, in ns: when the first run starts
T0_NS = 1_782_864_000 * 1_000_000_000


def record_runs(
    folder: Path,
    runs: int,
    samples: int,
    seed: int = 1,
    station_file: Path | None = None,
    start_ns: int = T0_NS,
) -> Path:
    """``runs`` runs (ids 1 to ``runs``) of station ``st1`` recorded into
    ``folder/recordings``, the first at ``start_ns``; that folder. ``station_file``: that
    station's runs into its recordings folder instead."""
    if station_file is None:
        folder.mkdir(parents=True, exist_ok=True)
        station_file = write_station_file(
            folder / "station.toml", folder / "recordings", ["tcp/127.0.0.1:1"]
        )
    loaded = load_station(station_file)
    recordings = loaded.recordings_folder
    station = loaded.station_id
    limits = FileLimits(1000 * MS, 1 << 40, 3600 * 1000 * MS)
    recorder = Recorder(recordings, limits, FileMetadata(loaded))
    rng = random.Random(seed)
    now_ns = start_ns

    def put(topic: str, message: object) -> None:
        recorder.write(classify(f"boltwatch/{station}/{topic}", encode(message), now_ns))

    every = max(1, samples // (EVENTS + 1))
    for run_id in range(1, runs + 1):
        started_ns = now_ns
        put("tool", ToolState(station, run_id, 7, 1, "running", now_ns))
        batch = []
        for n in range(samples):
            now_ns += MS
            share = n / samples
            sample = Sample(
                station,
                run_id,
                n,
                now_ns,
                round(190.0 * share + rng.gauss(0.0, 0.05), 3),  # the DBC's resolutions
                round(60.0 * share + rng.gauss(0.0, 0.01), 2),
                round(56_000.0 * share + rng.gauss(0.0, 5.0), 1),
            )
            batch.append(classify(f"boltwatch/{station}/samples", encode(sample), now_ns))
            if len(batch) == BATCH:
                recorder.write_samples(station, batch)
                batch = []
            if n % every == every - 1 and n // every < EVENTS:
                index = n // every + 1
                time_s = n / 1000
                event = factories.event(
                    run_id, index, station=station, time_ns=now_ns, time_s=time_s
                )
                put("events", event)
                put("intensity", Intensity(station, run_id, now_ns, 0.5, 0.5 * index))
            if n % 500 == 499:
                recorder.tick(now_ns)
        recorder.write_samples(station, batch)
        decision = StopDecision(
            station, run_id, now_ns, samples / 1000, "plateau_closest", "", 190.0, 55_800.0,
            56_000.0, now_ns + 5,
        )  # fmt: skip
        put("decision", decision)
        put("tool", ToolState(station, run_id, 7, 1, "done", now_ns + 1))
        summary = factories.summary(
            run_id, station=station, samples=samples, started_ns=started_ns, ended_ns=now_ns + 1
        )
        put("runs", summary)
        result = factories.result(
            run_id, station=station, time_ns=now_ns + 1, part_id=f"L1-P{run_id // 5:07d}"
        )
        put("results", result)
        now_ns += 27_000 * MS  # the next part's bolt: a run every 30 s or so
        recorder.tick(now_ns)
    recorder.close()
    return recordings
