"""A multi-spindle system on a real python-can virtual bus: the simulated rig's N spindles,
the acquisition's lanes and the station's predictor (its run bookkeeping, as at the edge),
in one process, no mocks.

Each spindle's frames are at the DBC's ids shifted by the stride, with its own Counter; the
acquisition pairs each spindle's samples, names each run's spindle and cycle (the last
CycleStart's sync id), and the predictor decides per spindle: each decision goes out as the
StopCommand at that spindle's id, and only that spindle stops. A spindle that ends early
waits for the others: the next cycle's runs start after the last run of the one before.
"""

from __future__ import annotations

import threading
import time
import uuid
from collections import defaultdict
from pathlib import Path

import can
import pytest

from services.acquisition.acquisition import Acquisition
from services.rig.frames import RigFrames
from services.rig.multi_spindle import MultiSpindleRig
from services.rig.realtime import RunSummary as RigSummary
from services.rig.realtime import ToolIdentity
from shared.config import LoadedStation, load_station
from shared.contract import (
    CycleResult,
    RunSummary,
    SpindleIds,
    StationDatabase,
    StopDecision,
    TighteningResult,
)
from shared.errors import CanDatabaseError
from shared.model import JointConstants
from tests.support.acquisition_bus import ListOutlet, StationPredictor
from tests.support.station_files import write_station

SPINDLES = 4
CYCLES = 2
FIRST_RUN = 5000
SAFETY_TIMEOUT_S = 60.0


def multi_spindle_station(folder: Path, spindles: int = SPINDLES) -> LoadedStation:
    return load_station(
        write_station(
            folder,
            replacements={
                "has_force_sensor = true": f"has_force_sensor = true\nspindles = {spindles}",
                "pause_between_runs_s = 0.3": "pause_between_runs_s = 0.0",
            },
        )
    )


def test_each_spindle_is_paired_decided_and_stopped_on_its_own_ids(tmp_path: Path) -> None:
    station = multi_spindle_station(tmp_path)
    config = station.config
    database = StationDatabase(station.dbc_path)
    program = config.program(2)  # short runs
    channel = f"spindles-{uuid.uuid4().hex}"
    predictor = StationPredictor(station)
    outlet = ListOutlet()
    rig_summaries: list[RigSummary] = []
    stop = threading.Event()
    with (
        can.Bus(interface="virtual", channel=channel) as tool_bus,
        can.Bus(interface="virtual", channel=channel) as station_bus,
    ):
        acquisition = Acquisition(
            "st1",
            True,
            station_bus,
            database,
            outlet,
            decider=predictor,
            spindles=SPINDLES,
            spindle_id_stride=config.can.spindle_id_stride,
        )
        rig = MultiSpindleRig(
            tool_bus,
            RigFrames(database),
            JointConstants.of(station.joint),
            config.rig,
            ToolIdentity(config.station.tool_id, True),
            tool_ids=[config.station.tool_of(k) for k in range(1, SPINDLES + 1)],
            id_stride=config.can.spindle_id_stride,
        )
        worker = threading.Thread(
            target=lambda: rig_summaries.extend(
                rig.run_many(program, FIRST_RUN, 11, stop, runs=CYCLES)
            )
        )
        worker.start()
        deadline = time.monotonic() + SAFETY_TIMEOUT_S
        while worker.is_alive() and time.monotonic() < deadline:
            acquisition.poll(0.01)
        stop.set()
        worker.join(SAFETY_TIMEOUT_S)
        while (message := station_bus.recv(0.05)) is not None:
            acquisition.handle(message)
        stats = acquisition.stats()
    assert not worker.is_alive()

    runs = range(FIRST_RUN, FIRST_RUN + SPINDLES * CYCLES)
    assert [s.run_id for s in rig_summaries] == list(runs)
    # every spindle's samples, in order, none missed; each in its own run
    by_run: dict[int, list[int]] = defaultdict(list)
    for sample in outlet.samples:
        by_run[sample.run_id].append(sample.sequence)
    for summary in rig_summaries:
        assert by_run[summary.run_id] == list(range(summary.samples)), summary.run_id
    assert stats.missed_samples == 0 and stats.counter_gaps == 0 and stats.unpaired == 0
    assert stats.unknown_ids == 0 and stats.decode_errors == 0

    # each run's states name its spindle and its cycle (spindle 1's run id, the sync id)
    started = [s for s in outlet.states if s.state == "running"]
    assert [(s.run_id, s.spindle, s.sync_id) for s in started] == [
        (run, (run - FIRST_RUN) % SPINDLES + 1, run - (run - FIRST_RUN) % SPINDLES) for run in runs
    ]
    assert [s.tool_id for s in started[:SPINDLES]] == [7, 8, 9, 10]
    # a spindle that ended early waited: the second cycle starts after the first one's last end
    ends = {s.run_id: s.time_ns for s in outlet.states if s.state in ("done", "aborted")}
    second_starts = [s.time_ns for s in started[SPINDLES:]]
    assert min(second_starts) >= max(ends[run] for run in runs[:SPINDLES])

    # decided per spindle: each decision a StopCommand at its spindle's id, or counted late
    decisions = predictor.of(StopDecision)
    assert {d.run_id for d in decisions} == set(runs)
    assert stats.stop_commands + stats.late_decisions == len(decisions)
    # a StopCommand stops its own spindle's run only (one that came after the tool's own
    # shutoff halted nothing more)
    obeyed = {s.run_id for s in rig_summaries if s.stop_source == "stop_command"}
    assert obeyed and obeyed <= {d.run_id for d in decisions}
    assert len(obeyed) <= stats.stop_commands

    summaries = predictor.of(RunSummary)
    results = predictor.of(TighteningResult)
    assert [(r.run_id, r.spindle, r.sync_id) for r in results] == [
        (s.run_id, s.spindle, s.sync_id) for s in summaries
    ]
    assert sorted(r.run_id for r in results) == list(runs)
    # each cycle's common result after its last spindle's summary: OK only when all are
    cycles = predictor.of(CycleResult)
    assert [c.sync_id for c in cycles] == [FIRST_RUN, FIRST_RUN + SPINDLES]
    for cycle in cycles:
        mine = {r.spindle: r for r in results if r.sync_id == cycle.sync_id}
        assert [(s.spindle, s.run_id, s.result) for s in cycle.spindles] == [
            (k, mine[k].run_id, mine[k].result) for k in range(1, SPINDLES + 1)
        ]
        assert cycle.result == ("OK" if all(r.result == "OK" for r in mine.values()) else "NOK")
        last = max(predictor.published.index(s) for s in summaries if s.sync_id == cycle.sync_id)
        assert predictor.published.index(cycle) == last + 1


def test_a_stride_that_lands_two_spindles_on_one_id_is_refused_naming_both() -> None:
    database = StationDatabase(Path(__file__).parents[4] / "config" / "can" / "station.dbc")
    with pytest.raises(CanDatabaseError, match="share id 0x101"):
        SpindleIds(database, 4, 1)
    with pytest.raises(CanDatabaseError, match="share id"):
        SpindleIds(database, 60, 2)
    ids = SpindleIds(database, 20, 2)
    assert ids.by_id[256 + 2 * 19].name == "ToolSensors" and ids.by_id[256 + 38].spindle == 20
    assert ids.by_id[96].name == "CycleStart"
