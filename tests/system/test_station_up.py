"""``boltwatch up`` end to end: real processes, zenoh on loopback, CAN over udp_multicast.

Checks what the station issue promises: runs are tightened, stopped by the
predictor's decision, recorded to MCAP with no sample lost between the CAN bus
and the recorder; a killed service is reported and everything stops; Ctrl-C
leaves nothing running.
"""

from __future__ import annotations

import signal
import subprocess
import time
from collections import defaultdict
from pathlib import Path

import pytest
from mcap.reader import make_reader

from shared.recordings import unfinished_files
from tests.support.disk_faults import tmpfs
from tests.support.station_files import (
    is_running,
    kill_all,
    process_report,
    write_station,
)
from tests.support.station_up import (
    read_recordings,
    run_up,
    services_of,
    start_up,
    wait_for_first_run,
)

pytestmark = pytest.mark.system


def test_up_tightens_stops_and_records_every_sample(tmp_path: Path) -> None:
    # two bolts per part: the three runs tighten two parts (the rig puts each part's id)
    station = write_station(tmp_path, replacements={"bolts_per_part = 4": "bolts_per_part = 2"})
    result = run_up(station, runs=3)
    assert "stop reason" in result.stdout and "recordings:" in result.stdout

    messages = read_recordings(tmp_path / "recordings")
    summaries = messages["boltwatch/st1/runs"]
    assert len(summaries) == 3
    samples_by_run: dict[int, list[int]] = defaultdict(list)
    for sample in messages["boltwatch/st1/samples"]:
        samples_by_run[sample["run_id"]].append(sample["sequence"])
        assert isinstance(sample["torque_nm"], float) and isinstance(sample["force_n"], float)
    for summary in summaries:
        sequences = sorted(samples_by_run[summary["run_id"]])
        # Nothing lost or duplicated between the CAN bus and the recorder.
        assert sequences == list(range(len(sequences))), summary["run_id"]
        assert len(sequences) == summary["samples"]
        assert summary["tool_state"] == "done"
        assert abs(summary["error_pct"]) < 10.0, summary
    bus = messages["boltwatch/st1/bus"][-1]
    assert bus["missed_samples"] == 0 and bus["counter_gaps"] == 0
    assert bus["samples"] == sum(len(s) for s in samples_by_run.values())

    decisions = messages["boltwatch/st1/decision"]
    assert decisions, "the predictor never decided to stop"
    assert len({d["run_id"] for d in decisions}) == len(decisions)  # one per run
    # each decision became a StopCommand, or came after the tool's own shutoff
    # (a loaded machine) and was counted late: never dropped unseen
    assert bus["stop_commands"] >= 1
    assert bus["stop_commands"] + bus["late_decisions"] == len(decisions)
    events = messages["boltwatch/st1/events"]
    assert len(events) >= 3 * 5  # the default program sticks and slips clearly
    for summary in summaries:  # every event the predictor counted is in the recording
        indexes = sorted(e["index"] for e in events if e["run_id"] == summary["run_id"])
        assert indexes == list(range(1, summary["events"] + 1)), summary["run_id"]

    # one TighteningResult per run on its channel, in the run's file, judged
    # against program 1's windows in the station file; its OK/NOK in up's table
    results = {r["run_id"]: r for r in messages["boltwatch/st1/results"]}
    assert len(messages["boltwatch/st1/results"]) == 3
    assert set(results) == {s["run_id"] for s in summaries}
    rows = [line.split() for line in result.stdout.splitlines() if line[:1].isdigit()]
    verdicts = {int(row[0]): row[7] for row in rows if len(row) > 7 and row[7] in ("OK", "NOK")}
    for summary in summaries:
        judged = results[summary["run_id"]]
        assert judged["source"] == "predictor" and judged["tightening_id"] == summary["run_id"]
        assert judged["final_force_n"]["value"] == summary["reached_force_n"]
        assert judged["final_torque_nm"]["value"] == summary["reached_torque_nm"]
        assert judged["final_angle_deg"]["value"] == summary["reached_angle_deg"]
        assert (judged["final_force_n"]["min"], judged["final_force_n"]["max"]) == (53e3, 59e3)
        force = summary["reached_force_n"]
        expected = "low" if force < 53e3 else "high" if force > 59e3 else "ok"
        assert judged["final_force_n"]["status"] == expected
        assert judged["result"] in ("OK", "NOK") and (judged["result"] == "OK") == (
            judged["nok_reasons"] == ""
        )
        assert verdicts[summary["run_id"]] == judged["result"]  # up's table says the same

    # Each result names the part the rig (the line's PLC) put before the run started:
    # the first two runs one part, the third the next; up's table and totals say so
    first = min(s["run_id"] for s in summaries)
    scans = messages["boltwatch/st1/part"]
    assert [scan["part_id"] for scan in scans] == [f"st1-P{first:06d}", f"st1-P{first + 2:06d}"]
    parts = {run_id: judged["part_id"] for run_id, judged in results.items()}
    assert parts == {
        first: scans[0]["part_id"],
        first + 1: scans[0]["part_id"],
        first + 2: scans[1]["part_id"],
    }
    table = [row for row in rows if len(row) > 7 and row[7] in ("OK", "NOK")]
    assert {int(row[0]): row[-1] for row in table} == parts
    assert ", 2 parts" in result.stdout


def test_killed_service_is_reported_and_the_rest_stop(tmp_path: Path) -> None:
    up = start_up(write_station(tmp_path), runs=100)
    try:
        wait_for_first_run(up)
        services = services_of(up)
        # the station's predictor decides in its acquisition (placement edge): no process
        assert set(services) == {"router", "recorder", "acquisition", "rig"}
        services_pids = list(services.values())
        subprocess.run(["kill", "-9", str(services["acquisition"])], check=True)
        output, _ = up.communicate(timeout=60)
    finally:
        if up.poll() is None:
            up.kill()
    assert up.returncode not in (0, None)
    assert "acquisition exited with status -9" in output
    time.sleep(0.5)
    alive = [pid for pid in services_pids if is_running(pid)]
    kill_all(alive)
    assert alive == []


def test_ctrl_c_stops_every_process_cleanly(tmp_path: Path) -> None:
    up = start_up(write_station(tmp_path), runs=100)
    try:
        wait_for_first_run(up)
        services_pids = list(services_of(up).values())
        assert len(services_pids) == 4  # router, recorder, acquisition (and predictor), rig
        up.send_signal(signal.SIGINT)
        output, _ = up.communicate(timeout=60)
    finally:
        if up.poll() is None:
            up.kill()
    assert up.returncode == 130, output
    assert "interrupted" in output
    alive = [pid for pid in services_pids if is_running(pid)]
    kill_all(alive)
    assert alive == []
    # Stopped cleanly: every MCAP file is complete (readable with its summary).
    for path in (tmp_path / "recordings").rglob("*.mcap"):
        with path.open("rb") as handle:
            assert make_reader(handle).get_summary() is not None, path


def test_services_stop_cleanly_when_up_is_killed_outright(tmp_path: Path) -> None:
    """SIGKILL to ``up`` (out-of-memory killer, a crash): no orphan keeps the bus and the
    ports, and the recorder still closes its files."""
    up = start_up(write_station(tmp_path), runs=100)
    try:
        wait_for_first_run(up)
        services_pids = list(services_of(up).values())
        assert len(services_pids) == 4
    finally:
        up.kill()
        up.communicate(timeout=60)
    deadline = time.monotonic() + 60
    while (alive := [pid for pid in services_pids if is_running(pid)]) and (
        time.monotonic() < deadline
    ):
        time.sleep(0.1)
    report = "\n".join(process_report(pid) for pid in alive)
    kill_all(alive)
    assert alive == [], report
    logs = list((tmp_path / "recordings" / "logs").rglob("*.log"))
    assert len(logs) >= 4, logs
    for log in logs:  # a stop that hung left at its deadline, its threads' stacks logged
        text = log.read_text(errors="replace")
        assert "its stop took more than" not in text, f"{log.name}:\n{text[-6000:]}"
    recordings = list((tmp_path / "recordings").rglob("*.mcap"))
    assert recordings
    for path in recordings:
        with path.open("rb") as handle:
            assert make_reader(handle).get_summary() is not None, path


def test_runs_not_recorded_are_named_and_up_exits_non_zero(tmp_path: Path) -> None:
    """The recordings folder is an 8 MB tmpfs, the recorder's free-space reserve 16 MB: no
    run file is opened; the runs are still tightened and decided, and ``up`` ends with one
    line naming the runs not recorded and exit status 1 (it used to say nothing, exit 0)."""
    reserve = {
        "flush_interval_s = 1.0": "flush_interval_s = 1.0\nfree_space_reserve_bytes = 16000000"
    }
    station = write_station(tmp_path, replacements=reserve)
    with tmpfs(tmp_path / "recordings", 8 << 20) as recordings:
        result = run_up(station, 1, status=1)
        (note,) = [line for line in result.stderr.splitlines() if "NOT RECORDED" in line]
        assert note.startswith("NOT RECORDED: 1 of 1 runs have no recording (st1 run ")
        assert "recorder.log" in note
        assert not list(recordings.rglob("*.mcap")) and unfinished_files(recordings) == []
        recorder_log = next(recordings.rglob("recorder.log")).read_text()
        assert "below the reserve of 16.0 MB" in recorder_log
