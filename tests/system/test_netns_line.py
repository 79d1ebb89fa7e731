"""Three stations and the line server on separate hosts (network namespaces).

The line server runs the zenoh router and the recorder; each station box runs
its own simulated rig on its own CAN bus (multicast on the box's loopback),
its acquisition and its predictor, all zenoh clients of the router over the
box's own cable. Every station tightens; station 3's cable is pulled for twelve
seconds in the middle; the stations' spools are off (store and forward, on by default,
loses nothing: ``test_store_and_forward.py``). The other two must be untouched (every run recorded,
no sample lost); station 3 must be reported down while cut off, its lost
samples counted, and its runs after the cable is back recorded in full.

Skips, with the reason, where network namespaces cannot be made; the
loopback variant of the same line is ``tests/system/test_line_up.py``.
"""

from __future__ import annotations

import itertools
import json
import subprocess
import time
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from mcap.reader import make_reader

from services.cli.station_supervisor import stop_process
from shared.recordings.mcap import RAW_ENCODING, RAW_REASON
from tests.support.netns_line import (
    LINE_ENDPOINT,
    Line,
    line_station_files,
    line_status,
    unavailable_reason,
    wait_until_up,
)

WHY_NOT = unavailable_reason()
pytestmark = pytest.mark.skipif(WHY_NOT is not None, reason=WHY_NOT or "")

STATIONS = 3
CUT_STATION = 3
RUNS = 16  # about two seconds a run: well past the cut (3 s + 12 s)
CUT_AFTER_S = 3.0
CUT_FOR_S = 12.0
ENDPOINT = LINE_ENDPOINT


@dataclass
class StationRecord:
    """What the recording holds of one station."""

    samples_by_run: dict[int, list[int]] = field(default_factory=lambda: defaultdict(list))
    summaries: list[dict[str, object]] = field(default_factory=list)
    last_bus: dict[str, int] = field(default_factory=dict)

    def gaps(self) -> int:
        return sum(
            1
            for sequences in self.samples_by_run.values()
            for a, b in itertools.pairwise(sequences)
            if b != a + 1
        )

    @property
    def samples(self) -> int:
        return sum(len(s) for s in self.samples_by_run.values())


def read_recordings(folder: Path) -> tuple[dict[str, StationRecord], list[str]]:
    """What each station's channels hold, and each message the recorder refused (its raw
    channels: a payload that arrived and does not decode, kept byte for byte, never a
    sample), named with its topic, why and its bytes."""
    records: dict[str, StationRecord] = defaultdict(StationRecord)
    refused: list[str] = []
    for path in sorted(folder.rglob("*.mcap")):
        with path.open("rb") as handle:
            for _schema, channel, message in make_reader(handle).iter_messages():
                if channel.message_encoding == RAW_ENCODING:
                    why = channel.metadata.get(RAW_REASON)
                    refused.append(f"{path.name} {channel.topic} ({why}): {message.data!r}")
                    continue
                station, topic = channel.topic.split("/")[1:3]
                record = records[station]
                body = json.loads(message.data)
                if topic == "samples":
                    record.samples_by_run[body["run_id"]].append(body["sequence"])
                elif topic == "runs":
                    record.summaries.append(body)
                elif topic == "bus" and body["time_ns"] >= record.last_bus.get("time_ns", 0):
                    record.last_bus = body
    return records, refused


def station_files(tmp_path: Path) -> list[Path]:
    # each station host runs its own predictor process; the spool off: a cut's loss is
    # counted exactly (with it, nothing is lost: tests/system/test_store_and_forward.py)
    spool_off = "\n[spool]\nenabled = false\n"
    return line_station_files(tmp_path, STATIONS, spool_off, placement="line")


def recorder_counts(status: dict[str, dict[str, object]]) -> dict[str, object]:
    """Per station, what the recorder counts missing, once no sample flows (None before)."""
    counts: dict[str, object] = {}
    for station, view in status.items():
        recorder = view.get("recorder")
        if isinstance(recorder, dict):
            flowing = view.get("samples_per_s") not in (0, 0.0, None)
            counts[station] = None if flowing else recorder.get("missing_samples")
    return counts


def settled_status(line: Line, timeout_s: float = 60.0) -> dict[str, dict[str, object]]:
    """The line's status once the recorder has drained: no sample flows, and two statuses in
    a row agree on what it counts missing.

    After the cut the router hands the recorder a backlog (15 s of lag was seen on a loaded
    machine); the acquisitions' last counters and the recorder's count of what is missing are
    final only when nothing flows and the count no longer moves. (Its message count never
    settles: the acquisitions' BusStats go on once a second.)
    """
    time.sleep(3.0)  # the acquisitions send their last counters
    deadline = time.monotonic() + timeout_s
    previous = line_status(line)
    while time.monotonic() < deadline:
        status = line_status(line)
        counts = recorder_counts(status)
        settled = len(counts) == STATIONS and None not in counts.values()
        if settled and counts == recorder_counts(previous):
            return status
        previous = status
    raise AssertionError(f"the line did not settle in {timeout_s} s: {json.dumps(previous)[:3000]}")


def test_three_hosts_one_cut_off_for_twelve_seconds(tmp_path: Path) -> None:
    files = station_files(tmp_path)
    logs = tmp_path / "logs"
    logs.mkdir()
    processes: list[tuple[str, subprocess.Popen[bytes]]] = []

    def start(line: Line, namespace: str, name: str, args: list[str]) -> subprocess.Popen[bytes]:
        process = line.boltwatch(namespace, args, logs / f"{name}.log")
        processes.append((name, process))
        return process

    with Line(STATIONS) as line:
        try:
            start(line, line.server, "router", ["serve", "router", "--listen", ENDPOINT])
            config_all = [str(path) for path in files]
            start(line, line.server, "recorder", ["serve", "recorder", "--config", *config_all])
            for index, path in enumerate(files, start=1):
                for service in ("acquisition", "predictor"):
                    args = ["serve", service, "--config", str(path)]
                    start(line, line.station(index), f"st{index}-{service}", args)
            wait_until_up(line, STATIONS, ("acquisition", "predictor", "recorder"))
            rigs = [
                start(
                    line,
                    line.station(index),
                    f"st{index}-rig",
                    ["serve", "rig", "--config", str(path), "--runs", str(RUNS), "--program", "2"],
                )
                for index, path in enumerate(files, start=1)
            ]
            time.sleep(CUT_AFTER_S)
            line.cut(CUT_STATION)
            cut_at = time.monotonic()
            # the status is asked late in the cut: a router that lags under load still hands
            # on what the cut station sent before its cable went (seen: 53 samples/s at 4 s)
            time.sleep(CUT_FOR_S * 0.5)
            during_cut: dict[str, dict[str, object]] = {}
            # a status that failed or heard nothing of the line under load is asked again,
            # while the cut lasts (each takes its 1.5 s window and a process start)
            while not during_cut and time.monotonic() - cut_at < CUT_FOR_S - 3.5:
                during_cut = line_status(line)
            time.sleep(max(CUT_FOR_S - (time.monotonic() - cut_at), 0.0))
            line.reconnect(CUT_STATION)
            for rig in rigs:
                assert rig.wait(120) == 0, "a rig failed; see the logs in " + str(logs)
            final = settled_status(line)
        finally:
            for _name, process in reversed(processes):
                stop_process(process)
    records, refused = read_recordings(tmp_path / "recordings")
    assert not refused, refused[:5]  # nothing on the line sends a payload that does not decode

    for index in range(1, STATIONS + 1):
        if index == CUT_STATION:
            continue
        record = records[f"st{index}"]
        assert len(record.summaries) == RUNS, f"st{index}: {len(record.summaries)} summaries"
        assert record.gaps() == 0
        assert record.last_bus["missed_samples"] == 0
        assert record.samples == record.last_bus["samples"], f"st{index} lost samples"

    cut = records[f"st{CUT_STATION}"]
    # the line server sees no sample of the cut station while the others' go on
    # (any rate: the window takes in pauses between runs, and a loaded machine runs its
    # rigs slower; 93 samples/s was seen with three other suites beside it)
    # (not listed at all is nothing seen too: under load the recorder's once-a-second
    # RecorderStats of the cut station can miss the 1.5 s window, and no token of it is left)
    assert during_cut.get(f"st{CUT_STATION}", {}).get("samples_per_s", 0.0) == 0.0, during_cut
    for index in (1, 2):
        rate = during_cut[f"st{index}"]["samples_per_s"]
        assert isinstance(rate, float) and rate > 0.0, during_cut
    # end to end, whatever zenoh noticed of the cut: the recorder's count of
    # samples published and never received is exactly what the recording lacks
    for index in range(1, STATIONS + 1):
        record = records[f"st{index}"]
        recorder = final[f"st{index}"]["recorder"]
        assert isinstance(recorder, dict), final
        lacking = record.last_bus["samples"] - record.samples
        assert recorder["missing_samples"] == lacking, (f"st{index}", recorder)
        assert lacking > 0 if index == CUT_STATION else lacking == 0  # sent while cut off
    last_run = max(cut.samples_by_run)
    sequences = cut.samples_by_run[last_run]
    assert sequences == list(range(sequences[0], sequences[0] + len(sequences)))
