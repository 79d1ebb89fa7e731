"""Each station service killed with SIGKILL mid-run: the tool never tightens blind, the
recording keeps a bounded part, and the restarted service makes the next run normal.

One station (router, recorder, predictor, acquisition, rig on program 2) runs for the
whole module (:mod:`tests.support.live_station`); each test kills one service while a
run is under way, then starts it again as compose ``restart:`` or systemd would:

- what the tool does is read from the CAN bus itself: the killed run ends at the
  target (the rig's own conventional shutoff) or on a hard limit, never beyond
  ``max_force_n``;
- what the recording keeps: a gap-free prefix of the run's samples (the recorder:
  all but about its last flush interval, and ``boltwatch recover`` makes its file
  valid);
- the first run that starts after the restart is normal: the predictor decides,
  the run is summarised, and its samples are recorded with none missing.
"""

from __future__ import annotations

import os
import signal
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from mcap.reader import make_reader

from shared.recordings.mcap import RecordingScan
from tests.support.live_station import (
    LiveStation,
    check_next_run_normal,
    live_station,
    recorded_sequences,
)
from tests.support.router_process import boltwatch

pytestmark = pytest.mark.system

SAMPLES_BEFORE_KILL = 150  # the run is well under way, before any stop decision


@pytest.fixture(scope="module")
def station(tmp_path_factory: pytest.TempPathFactory) -> Iterator[LiveStation]:
    with live_station(tmp_path_factory.mktemp("kills")) as running:
        running.wait_runs_summarised(1)  # the station works before anything is killed
        yield running


def wait_mid_run(station: LiveStation) -> int:
    """The run under way once it is SAMPLES_BEFORE_KILL samples in, before any decision."""

    def under_way() -> bool:
        run_id = station.running_run()
        return (
            run_id is not None
            and len(station.can.runs()[run_id].forces_n) >= SAMPLES_BEFORE_KILL
            and not station.decided(run_id)
        )

    station.wait_for(under_way, "a run under way")
    run_id = station.running_run()
    assert run_id is not None
    return run_id


def kill_mid_run(station: LiveStation, service: str) -> int:
    """Kill ``service`` while a run is SAMPLES_BEFORE_KILL samples in; that run's id."""
    killed_run = wait_mid_run(station)
    station.kill(service)
    return killed_run


def assert_tool_stopped_safely(station: LiveStation, run_id: int) -> float:
    """The run ended at/near the target or on a limit, never beyond max; its final force."""
    station.wait_for(lambda: station.can.runs()[run_id].ended, f"run {run_id} to end")
    program = next(p for p in station.loaded.config.programs if p.id == 2)
    forces = station.can.runs()[run_id].forces_n
    assert program.max_force_n is not None and program.target_force_n is not None
    assert max(forces) <= program.max_force_n
    final_n = forces[-1]
    on_target = abs(final_n - program.target_force_n) <= 0.1 * program.target_force_n
    assert on_target or final_n >= program.max_force_n * 0.98, final_n
    return final_n


def wait_recording_settled(station: LiveStation, run_id: int) -> None:
    """Until the run's recorded samples stop growing over two flush intervals."""
    counts = [-1]

    def settled() -> bool:
        counts.append(len(recorded_sequences(station.recordings, run_id)))
        return counts[-1] > 0 and counts[-1] == counts[-2]

    station.wait_for(settled, f"the recording of run {run_id} to settle", poll_s=2.0)


def recover_killed_file(station: LiveStation, run_id: int, recovered: Path) -> list[int]:
    """``boltwatch recover`` on the killed recorder's file (under its writing name: no run
    file's name is on a broken file); the recovered sample sequences."""
    assert not list(station.recordings.rglob(f"st1_run{run_id}_*.mcap"))
    (killed_file,) = sorted(station.recordings.rglob(f".st1_run{run_id}_*.mcap.writing"))
    result = boltwatch("recover", str(killed_file), "--out", str(recovered), timeout_s=None)
    assert result.returncode == 0, result.stderr
    with recovered.open("rb") as handle:  # the mcap library's own indexed reader: valid file
        return [
            message.sequence
            for _, channel, message in make_reader(handle).iter_messages(log_time_order=False)
            if channel.topic.endswith("/samples")
        ]


@pytest.mark.parametrize("service", ["predictor", "acquisition", "recorder"])
def test_a_service_killed_mid_run(station: LiveStation, service: str, tmp_path: Path) -> None:
    killed_run = kill_mid_run(station, service)
    final_n = assert_tool_stopped_safely(station, killed_run)
    assert not station.decided(killed_run) or service == "recorder"

    if service == "recorder":
        got = recover_killed_file(station, killed_run, tmp_path / "recovered.mcap")
    else:
        # The recorder lives on: what reached it before the kill is on disk within ~1 s
        # (how much reached it depends on how far the acquisition lagged the bus).
        wait_recording_settled(station, killed_run)
        got = recorded_sequences(station.recordings, killed_run)
    assert got == list(range(len(got))), "the recording keeps a gap-free prefix"
    print(f"{service} killed in run {killed_run}: final force {final_n:.0f} N, kept {len(got)}")

    station.start(service)
    station.wait_alive((service,))
    if service == "recorder":  # it finished the file it was killed in, under its name (or
        # removed it: killed before its first flush, it held no message)
        assert not list(station.recordings.rglob(f".st1_run{killed_run}_*.writing"))
        assert recorded_sequences(station.recordings, killed_run) == got
        for finished in station.recordings.rglob(f"st1_run{killed_run}_*.mcap"):
            scan = RecordingScan(finished)
            assert sum(1 for _ in scan.messages()) > 0 and scan.complete
    check_next_run_normal(station)


def test_a_predictor_paused_mid_run_is_a_late_decision_not_the_stop_reason(
    station: LiveStation,
) -> None:
    """A predictor paused 3 s (SIGSTOP / SIGCONT): the tool stopped by its own
    shutoff and the acquisition ignored the late decision, but the summary said
    ``plateau_closest``. What stopped the tool is the acquisition's word now."""
    run_id = wait_mid_run(station)
    predictor = station.process("predictor")
    os.kill(predictor.pid, signal.SIGSTOP)
    try:
        station.wait_for(lambda: station.can.runs()[run_id].ended, f"run {run_id} to end")
        time.sleep(3.0)  # paused for 3 s
    finally:
        os.kill(predictor.pid, signal.SIGCONT)
    assert_tool_stopped_safely(station, run_id)
    summary = None

    def summarised() -> bool:
        nonlocal summary
        summary = next((s for s in station.summaries() if s.run_id == run_id), None)
        return summary is not None

    station.wait_for(summarised, f"the summary of run {run_id}")
    assert summary is not None
    assert summary.stop_reason is None, summary  # the tool stopped by itself
    assert summary.late_decision is not None, summary  # the predictor decided, too late
    check_next_run_normal(station)


def test_an_edge_station_whose_acquisition_dies_stops_by_the_tool_and_comes_back(
    tmp_path_factory: pytest.TempPathFactory,
) -> None:
    """The edge layout: the station's predictor lives in its acquisition, so killing that
    process kills both; the tool stops by its own shutoff (never blind), and the restarted
    acquisition decides the next run again (the fault table still holds)."""
    with live_station(tmp_path_factory.mktemp("edge-kill"), placement="edge") as station:
        station.wait_runs_summarised(1)
        killed_run = kill_mid_run(station, "acquisition")
        assert_tool_stopped_safely(station, killed_run)
        assert not station.decided(killed_run)
        station.start("acquisition")
        station.wait_alive(("acquisition", "predictor"))
        check_next_run_normal(station)
