"""The line's router killed mid-run and restarted: every service reconnects on its own.

Router, recorder, predictor, acquisition and rig run as ``boltwatch serve``
processes; the test SIGKILLs the router while the rig tightens joints one
after the other, restarts it on the same endpoint a few seconds later, and
checks, without restarting any service (and with the station's spool off, so that
what an outage costs is counted: with it nothing is lost,
``tests/system/test_store_and_forward.py``):

- the acquisition counted the samples it published with no router
  (``BusStats.unsent_samples``) and logged the outage with its length;
- those samples are missing from the recording (the rig's log says how many
  samples each run had), and nothing else is; the recorder's own end-to-end
  count (``RecorderStats.missing_samples``) is exactly what the recording lacks;
- the runs that lost samples follow one another and are no more than the
  outage overlaps: its length as the acquisition measured it (the sleep, the new
  router's start, which takes seconds on a loaded machine, and the reconnect)
  over the shortest run and its pause, plus one;
- the run(s) the predictor could not stop ended at the rig's conventional
  shutoff, at the target: the tool never tightens blind;
- a run after the outage (one started once the recorder was heard again: the
  recorder may reconnect after the acquisition, and a run started in between
  loses its first samples) is recorded whole and stopped by the predictor.
"""

from __future__ import annotations

import math
import re
import signal
import subprocess
import time
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import pytest
import zenoh

from services.cli.station_supervisor import stop_process
from shared.config import load_station
from shared.contract import RunSummary, Sample, channels, decode
from shared.recordings.mcap import RAW_ENCODING, RecordingScan
from shared.runtime import zenoh_config
from tests.support.listener import Listener
from tests.support.station_files import free_tcp_port, serve, write_station

pytestmark = pytest.mark.system

STATION = "st1"
FIRST_RUN = 5000
TARGET_FORCE_N = 56_000.0
OUTAGE_S = 3.0
RECONNECT_PERIOD_MAX_S = 0.5
START_TIMEOUT_S = 30.0
RUN_TIMEOUT_S = 30.0
RIG_RUN = re.compile(r"run (\d+): (\w+) by (\w+), force (\d+) N, .* (\d+) samples, ")
#: how far the acquisition's link flag may lag the link, in samples at 1 kHz: zenoh's event
#: callback waits for the GIL, a few ms on a quiet machine, 47 ms seen at load 17
LINK_EVENT_SAMPLES = 100


#: what the test hears of the station on zenoh
TOPICS = (channels.RUNS.topic, channels.BUS.topic, channels.RECORDER.topic)


@dataclass(frozen=True)
class RigRun:
    state: str
    stop_source: str
    force_n: float
    samples: int


def rig_runs(log: Path) -> dict[int, RigRun]:
    runs = {}
    for match in RIG_RUN.finditer(log.read_text()):
        run_id, state, source, force, samples = match.groups()
        runs[int(run_id)] = RigRun(state, source, float(force), int(samples))
    return runs


def recorded(folder: Path) -> tuple[dict[int, list[int]], dict[int, RunSummary]]:
    """Sample sequences per run and RunSummaries, from every MCAP file."""
    sequences: dict[int, list[int]] = {}
    summaries: dict[int, RunSummary] = {}
    for path in sorted(folder.rglob("*.mcap")):
        scan = RecordingScan(path)
        for _, channel, message in scan.messages():
            # a raw channel holds what the recorder refused, byte for byte: none is sent here
            assert channel.message_encoding != RAW_ENCODING, (path, channel, message.data)
            if channel.topic.endswith("/samples"):
                sample = decode(Sample, message.data)
                sequences.setdefault(sample.run_id, []).append(sample.sequence)
            elif channel.topic.endswith("/runs"):
                summary = decode(RunSummary, message.data)
                summaries[summary.run_id] = summary
    return sequences, summaries


def test_services_reconnect_after_the_router_is_killed(tmp_path: Path) -> None:
    port = free_tcp_port()
    endpoint = f"tcp/127.0.0.1:{port}"
    path = write_station(
        tmp_path,
        zenoh_port=port,
        placement="line",  # the line's predictor, reconnecting like every service
        replacements={
            'mode = "client"': f'mode = "client"\nreconnect_period_max_s = {RECONNECT_PERIOD_MAX_S}'
        },
    )
    # the spool off: what the outage costs a station without store and forward is counted
    # exactly (with it, nothing is lost: tests/system/test_store_and_forward.py)
    path.write_text(path.read_text() + "\n[spool]\nenabled = false\n")
    pause_s = load_station(path).config.rig.pause_between_runs_s
    logs = {n: tmp_path / f"{n}.log" for n in ("router", "recorder", "predictor", "acq", "rig")}
    router = serve(["router", "--listen", endpoint], logs["router"])
    services = [
        serve(["recorder", "--config", str(path)], logs["recorder"]),
        serve(["predictor", "--config", str(path)], logs["predictor"]),
        serve(["acquisition", "--config", str(path), "--stats-interval-s", "0.2"], logs["acq"]),
    ]
    rig: subprocess.Popen[bytes] | None = None
    config = zenoh_config(
        "client", [endpoint], reconnect_period_max_ms=round(RECONNECT_PERIOD_MAX_S * 1e3)
    )
    try:
        with zenoh.open(config) as session:
            heard = Listener(session, STATION, TOPICS)
            try:
                heard.wait(lambda: heard.of("bus"), "the acquisition's BusStats", START_TIMEOUT_S)
                # the recorder hears the station before the first run: what it counts
                # from then on is the whole of what the recording lacks
                heard.wait(
                    lambda: any(stats.messages > 0 for stats in heard.of("recorder")),
                    "the recorder hearing the station",
                    START_TIMEOUT_S,
                )
                rig_args = ["rig", "--config", str(path), "--program", "1"]
                rig = serve([*rig_args, "--first-run-id", str(FIRST_RUN)], logs["rig"])
                heard.wait(
                    lambda: any(s.stop_reason for s in heard.of("runs")),
                    "a run stopped by the predictor before the outage",
                    RUN_TIMEOUT_S,
                )
                router.send_signal(signal.SIGKILL)
                router.wait(10)
                time.sleep(OUTAGE_S)  # the fault itself: the line has no router this long
                stats_before = len(heard.of("recorder"))  # none can come while no router is
                router = serve(["router", "--listen", endpoint], logs["router"])
                # the recorder reconnects on its own schedule, after the acquisition at times
                # (a run that started just then loses its first samples: seen, 4): the run
                # awaited is one that started once the recorder was heard again
                heard.wait(
                    lambda: len(heard.of("recorder")) > stats_before,
                    "the recorder back on the line",
                    RUN_TIMEOUT_S,
                )
                back_ns = heard.of("recorder")[stats_before].time_ns
                heard.wait(
                    lambda: any(
                        s.stop_reason == "plateau_closest" and s.started_ns > back_ns
                        for s in heard.of("runs")
                    ),
                    "a run started after the restart stopped early by the predictor",
                    RUN_TIMEOUT_S * 2,
                )
                stop_process(rig, grace_s=10.0)
                acquisition = services[-1]
                stop_process(acquisition, grace_s=10.0)  # publishes its final BusStats
                heard.wait(
                    lambda: (
                        heard.of("bus")[-1].samples > 0 and heard.of("bus")[-1].unsent_samples > 0
                    ),
                    "the final BusStats",
                    5.0,
                )
                final_bus_ns = heard.of("bus")[-1].time_ns
                heard.wait(
                    lambda: (
                        heard.of("recorder")
                        and heard.of("recorder")[-1].time_ns > final_bus_ns + 10**9
                    ),
                    "the recorder's count after the final BusStats",
                    5.0,
                )
            finally:
                heard.close()
    finally:
        for process in [*([rig] if rig else []), *reversed(services), router]:
            stop_process(process, grace_s=10.0)

    stats = heard.of("bus")[-1]
    runs = {r: run for r, run in rig_runs(logs["rig"]).items() if run.stop_source != "service_stop"}
    sequences, summaries = recorded(tmp_path / "recordings")
    missing = {
        run_id: run.samples - len(set(sequences.get(run_id, []))) for run_id, run in runs.items()
    }
    outage_runs = [run_id for run_id, lost in missing.items() if lost > 0]
    print(
        f"unsent {stats.unsent_samples}, missing from the recording {sum(missing.values())} "
        f"in runs {outage_runs}; bus missed {stats.missed_samples}; "
        f"recorder missing {heard.of('recorder')[-1].missing_samples}; "
        f"stop sources {Counter(r.stop_source for r in runs.values())}"
    )
    print("acquisition:", *re.findall(r".*router back after.*", logs["acq"].read_text()))

    # The outage was counted and logged once, with its length.
    outage_lines = re.findall(
        r"router back after ([\d.]+) s; (\d+) samples", logs["acq"].read_text()
    )
    assert len(outage_lines) == 1, logs["acq"].read_text()[-2000:]
    assert float(outage_lines[0][0]) >= OUTAGE_S * 0.9
    assert stats.unsent_samples >= 0.3 * OUTAGE_S * 1000  # runs take most of the outage
    # What was counted unsent is missing from the recording, and little else is. The
    # acquisition's link flag follows zenoh's link events, a few ms after the transport:
    # a sample put in between is counted unsent yet may arrive (seen: 2675 unsent, 2674
    # missing), so the unsent count is an estimate within LINK_EVENT_SAMPLES.
    lost_in_recording = sum(missing.values())
    assert stats.unsent_samples <= lost_in_recording + stats.missed_samples + LINK_EVENT_SAMPLES
    assert lost_in_recording <= stats.unsent_samples + 1000 * RECONNECT_PERIOD_MAX_S * 2
    # The runs that lost samples are the ones the outage overlapped, one after the other: as
    # many as fit in it, plus one it started in. The outage is the sleep plus the new router's
    # start (a Python process: under a second on a quiet machine, 5 s at load 15 to 18, where
    # outages of 7.9 and 8.3 s touched 4 and 5 runs) plus the reconnect, so it is taken as
    # measured, with the recorder's later reconnect.
    outage_s = float(outage_lines[0][0]) + 2 * RECONNECT_PERIOD_MAX_S
    period_s = min(run.samples for run in runs.values()) / 1e3 + pause_s
    most = math.ceil(outage_s / period_s) + 1
    assert 1 <= len(outage_runs) <= most, (missing, outage_s, period_s)
    assert outage_runs == list(range(outage_runs[0], outage_runs[-1] + 1)), missing
    assert all(lost >= 0 for lost in missing.values()), missing
    # The recorder counted the loss itself, to the sample, whatever the runs it fell in.
    recorded_samples = sum(len(set(run_sequences)) for run_sequences in sequences.values())
    assert heard.of("recorder")[-1].missing_samples == stats.samples - recorded_samples
    # No run tightened blind: the ones the predictor could not stop hit the shutoff at target.
    unstopped = [r for r in outage_runs if runs[r].stop_source != "stop_command"]
    assert unstopped, f"no run ended during the outage: {runs}"
    for run_id in unstopped:
        run = runs[run_id]
        assert run.stop_source == "shutoff_force", run
        assert abs(run.force_n - TARGET_FORCE_N) / TARGET_FORCE_N < 0.05, run
    # After the outage every run is recorded whole and the predictor decides again; its
    # StopCommand reaches the tool (a target_reached decision may tie with the rig's shutoff,
    # and on a loaded machine the line's predictor may decide after the tool stopped by
    # itself: a late decision, seen at load 15; the awaited run was stopped early by it).
    after = [r for r in runs if r > max(outage_runs)]
    assert after, f"no run after the outage: {runs}"
    for run_id in after:
        assert missing[run_id] <= stats.missed_samples, (run_id, missing)
        summary = summaries.get(run_id)
        assert summary is not None, run_id
        assert summary.stop_reason is not None or summary.late_decision is not None, summary
    early = [r for r in after if summaries[r].stop_reason == "plateau_closest"]
    assert early and all(runs[r].stop_source == "stop_command" for r in early), runs
