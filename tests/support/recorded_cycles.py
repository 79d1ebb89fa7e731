"""Multi-spindle cycles recorded as the recorder writes them, and their results stored as
``results rebuild`` stores them: the real :class:`Recorder` (MCAP, no Rerun, no zenoh) fed
every spindle's run of each cycle on a simulated 1 kHz clock, then the real results store
filled from the files.

Cycle ``c`` (from 0) of ``spindles`` spindles has the sync id ``SYNC + c`` and the runs
``RUN0 + c * 10 + k`` (spindle ``k + 1``), of part ``P<c>``; every spindle's run starts
together (spindle 1 first: the cycle's one file is named by its run), their samples
interleaved, each spindle's torque a little higher than the one before (so the curves
differ); in cycle 1, spindle 3 is NOK (torque low), so that cycle is NOK. Each cycle's
common result is put as the predictor puts it (:func:`shared.quality.cycle_result`).
"""

from __future__ import annotations

import time
from pathlib import Path

from services.recorder.live.recorder import Recorder
from services.recorder.live.run_files import FileLimits
from shared.config import LoadedStation, load_station
from shared.contract import JudgedFigure, Sample, ToolState, encode
from shared.quality import cycle_result
from shared.recordings import FileMetadata, classify
from shared.results import ResultsStore, station_store
from shared.results.recordings_reading import fill_from_recordings, station_recordings
from tests.support import factories
from tests.support.live_recorder import write_station_file

MS = 1_000_000
SYNC = 7000
RUN0 = 5000
#: 2026-07-01 00:00 UTC, in ns: when the first cycle starts
T0_NS = 1_782_864_000 * 1_000_000_000
#: the NOK spindle of cycle 1 and its reason
NOK_SPINDLE = 3
NOK_REASON = "torque low"


def cycle_runs(cycle: int, spindles: int) -> list[int]:
    """The run ids of cycle ``cycle``, in spindle order."""
    return [RUN0 + cycle * 10 + k for k in range(spindles)]


def record_cycles(folder: Path, cycles: int = 2, spindles: int = 4, samples: int = 300) -> Path:
    """``cycles`` cycles of ``spindles`` spindles of st1 recorded into ``folder/recordings``
    and stored in its ``results.sqlite``; the station file (``folder/station.toml``)."""
    folder.mkdir(parents=True, exist_ok=True)
    station_file = write_station_file(
        folder / "station.toml",
        folder / "recordings",
        ["tcp/127.0.0.1:1"],
        station={"spindles": spindles},
    )
    loaded = load_station(station_file)
    limits = FileLimits(1000 * MS, 1 << 40, 3600 * 1000 * MS)
    recorder = Recorder(loaded.recordings_folder, limits, FileMetadata(loaded))
    now_ns = T0_NS
    for cycle in range(cycles):
        now_ns = _record_cycle(recorder, cycle, spindles, samples, now_ns)
        now_ns += 20_000 * MS
        recorder.tick(now_ns)
    recorder.close()
    _store(loaded)
    return station_file


def _record_cycle(recorder: Recorder, cycle: int, spindles: int, samples: int, t: int) -> int:
    def put(topic: str, message: object, at_ns: int) -> None:
        recorder.write(classify(f"boltwatch/st1/{topic}", encode(message), at_ns))

    sync_id = SYNC + cycle
    runs = cycle_runs(cycle, spindles)
    for k, run in enumerate(runs):
        state = ToolState("st1", run, 7 + k, 1, "running", t + k, spindle=k + 1, sync_id=sync_id)
        put("tool", state, t + k)
    for n in range(samples):
        at = t + 10 + n * MS
        for k, run in enumerate(runs):
            share = n / samples
            sample = Sample(
                "st1", run, n, at, round((180.0 + 5 * k) * share, 3), round(50.0 * share, 2),
                round(56_000.0 * share, 1),
            )  # fmt: skip
            put("samples", sample, at)
    end = t + samples * MS + 20
    results = {}
    for k, run in enumerate(runs):
        nok = cycle == 1 and k + 1 == NOK_SPINDLE
        torque = JudgedFigure(150.0, 180.0, 240.0, "low") if nok else None
        result = factories.result(
            run, part_id=f"P{cycle}", spindle=k + 1, sync_id=sync_id, tool_id=7 + k,
            time_ns=end + k, result="NOK" if nok else "OK",
            nok_reasons=NOK_REASON if nok else "",
            **({"final_torque_nm": torque} if torque is not None else {}),
        )  # fmt: skip
        results[k + 1] = result
        summary = factories.summary(
            run, tool_id=7 + k, samples=samples, started_ns=t, ended_ns=end + k,
            spindle=k + 1, sync_id=sync_id,
        )  # fmt: skip
        done = ToolState("st1", run, 7 + k, 1, "done", end + k, spindle=k + 1, sync_id=sync_id)
        put("tool", done, end + k)
        put("results", result, end + k)
        put("runs", summary, end + k)
    put("cycles", cycle_result("st1", sync_id, spindles, results), end + spindles)
    return end + spindles


def _store(loaded: LoadedStation) -> None:
    folder = loaded.recordings_folder
    with ResultsStore(station_store(loaded)) as store:
        fill_from_recordings(store, station_recordings(folder, ["st1"]), {}, "line", time.time_ns)
