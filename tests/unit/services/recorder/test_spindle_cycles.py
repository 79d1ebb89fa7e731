"""A multi-spindle station's cycle in the recorder (real zenoh on loopback, real MCAP read
back): one file per cycle holding every spindle's run (named by the first to start),
finished after the cycle's common result, not after a spindle's summary; each spindle's
samples in order in their own run; the results store has every spindle's tightening with its
cycle; the wear ledger counts each spindle's tool."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path
from typing import Any

import zenoh

from shared.config import LoadedStation, load_station
from shared.contract import (
    CycleResult,
    CycleSpindle,
    Sample,
    SampleBatch,
    ToolState,
    decode,
)
from shared.recordings.mcap import RecordingScan
from shared.results import ResultsQuery, ResultsStore, station_store
from shared.runtime import zenoh_config
from shared.wear import WearLedger
from tests.support import factories
from tests.support.live_recorder import (
    RunningRecorder,
    free_port,
    publish,
    wait_until,
    write_station_file,
)
from tests.support.recorded_runs import T0_NS

SPINDLES = 4
SYNC = 7000
SAMPLES = 120


def cycle_messages() -> list[tuple[str, Any]]:
    """A cycle of four spindles as an edge station publishes it: the runs start together, their
    samples interleaved in batches of one run each, spindle 2 ends first and waits."""
    t = T0_NS
    runs = [SYNC + k for k in range(SPINDLES)]
    out: list[tuple[str, Any]] = [
        ("tool", ToolState("st1", run, 7 + k, 1, "running", t + k, spindle=k + 1, sync_id=SYNC))
        for k, run in enumerate(runs)
    ]
    for start in range(0, SAMPLES, 10):
        for run in runs:
            samples = [
                factories.sample(run, n, time_ns=t + 10 + n * 1_000_000)
                for n in range(start, start + 10)
            ]
            out.append(("sample_batches", SampleBatch("st1", t + start * 10**6, samples)))
    end = t + SAMPLES * 1_000_000
    order = [1, 0, 2, 3]  # spindle 2's run ends first
    results = []
    for k in order:
        run = runs[k]
        result = factories.result(
            run, part_id="P7000", spindle=k + 1, sync_id=SYNC, tool_id=7 + k, time_ns=end + k
        )
        results.append(result)
        summary = factories.summary(
            run,
            tool_id=7 + k,
            samples=SAMPLES,
            started_ns=t,
            ended_ns=end + k,
            spindle=k + 1,
            sync_id=SYNC,
        )
        out += [
            ("tool", ToolState("st1", run, 7 + k, 1, "done", end + k, spindle=k + 1, sync_id=SYNC)),
            ("results", result),
            ("runs", summary),
        ]
    cycle = CycleResult(
        station="st1",
        sync_id=SYNC,
        time_ns=end + 3,
        part_id="P7000",
        program_id=1,
        result="OK",
        nok_reasons="",
        source="predictor",
        spindles=[CycleSpindle(k + 1, run, "OK") for k, run in enumerate(runs)],
    )
    return [*out, ("cycles", cycle)]


def test_a_cycle_is_one_file_its_spindles_each_a_run_stored_with_their_cycle(
    tmp_path: Path,
) -> None:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    path = write_station_file(
        tmp_path / "station.toml",
        tmp_path / "recordings",
        listen=[endpoint],
        station={"spindles": SPINDLES},
    )
    station: LoadedStation = load_station(path)
    recorder = RunningRecorder(station)
    session = zenoh.open(zenoh_config("peer", connect=[endpoint]))
    folder = station.recordings_folder
    try:
        publish(session, cycle_messages())
        # the cycle's file is finished (under its name) a grace after the cycle's result, with
        # no next cycle
        wait_until(lambda: len(list(folder.glob("st1/*/st1_run*.mcap"))) == 1, "the cycle file")
        target = station_store(station)

        def stored() -> int:
            try:
                with ResultsStore(target, create=False) as store:
                    found = store.find(ResultsQuery())
            except Exception:
                return 0
            return sum(1 for s in found if s.cycle is not None)

        wait_until(lambda: stored() == SPINDLES, "every spindle's result with its cycle")
    finally:
        session.close()
        recorder.finish()
    (cycle_file,) = folder.glob("st1/*/st1_run*.mcap")
    assert cycle_file.name.startswith(f"st1_run{SYNC}_")
    scan = RecordingScan(cycle_file)
    sequences: dict[int, list[int]] = defaultdict(list)
    for _, _, message in scan.messages("/samples"):
        sample = decode(Sample, message.data)
        sequences[sample.run_id].append(sample.sequence)
    assert sequences == {SYNC + k: list(range(SAMPLES)) for k in range(SPINDLES)}
    topics: dict[str, int] = defaultdict(int)
    for _, channel, _ in scan.typed_messages():
        topics[channel.topic.split("/", 2)[2]] += 1
    assert (topics["results"], topics["runs"], topics["cycles"], topics["tool"]) == (4, 4, 1, 8)

    with ResultsStore(station_store(station), create=False) as store:
        found = store.find(ResultsQuery(part_id="P7000", oldest_first=True))
    assert sorted((s.result.spindle, s.result.run_id) for s in found) == [
        (k + 1, SYNC + k) for k in range(SPINDLES)
    ]
    assert {(s.cycle.sync_id, s.cycle.result) for s in found if s.cycle} == {(SYNC, "OK")}
    assert {s.recording for s in found} == {str(cycle_file.resolve())}

    with WearLedger(folder / "wear.sqlite") as ledger:
        tools = {row.tool_id: row.runs for row in ledger.tools()}
    assert tools == {7: 1, 8: 1, 9: 1, 10: 1}  # each spindle's tool, its own wear
