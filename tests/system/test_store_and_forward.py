"""Nothing lost when the line's network drops: three station boxes, cables cut, the recorder killed.

The line server (a network namespace) runs the router and the recorder; each
station box its simulated rig and its acquisition (which hosts the station's
predictor: placement edge, the default), a zenoh client of the router over
the box's own cable, spooling what it puts toward the line (``[spool]``, on by
default). While every station tightens:

1. station 2's and station 3's cables are pulled for :data:`CUT_S`; station
   2's acquisition is restarted (SIGTERM, started again) while its cable is out;
2. the cables back, the line's recorder is killed (SIGKILL) for :data:`CUT_S`,
   then started again.

Then every run of every station is in the recordings whole: its tool states,
every sample (sequences 0..n-1, n as its summary says), every event the
summary counts, its decision, result and summary; the wear ledger counts
every run once; the recorder says no sample is missing and no run waits in a
spool. Exactly once: what the killed recorder had filed and not yet
acknowledged, sent again by the stations, is recognised by the restarted
recorder in the files it finished (their spool marks) and not filed again.
Skips, with the reason, where network namespaces cannot be made.
"""

from __future__ import annotations

import json
import signal
import sqlite3
import subprocess
import time
from collections import Counter, defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from services.cli.station_supervisor import stop_process
from shared.recordings.mcap import RecordingScan
from shared.wear import ledger_path
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
CUT_S = 20.0
#: about two seconds a run: the rigs tighten through both faults (5 s + 2 CUT_S + 10 s)
#: and some time after
RUNS = 40
ENDPOINT = LINE_ENDPOINT


@dataclass
class RunRecord:
    """What the recordings hold of one run."""

    samples: Counter[int] = field(default_factory=Counter)  # sequence -> times recorded
    files: set[Path] = field(default_factory=set)  # the files holding its samples
    topics: Counter[str] = field(default_factory=Counter)
    summary: dict[str, Any] | None = None


def read_recordings(folder: Path) -> dict[str, dict[int, RunRecord]]:
    """Per station and run, everything recorded (a killed recorder's files read as far as
    they are whole)."""
    runs: dict[str, dict[int, RunRecord]] = defaultdict(lambda: defaultdict(RunRecord))
    for path in sorted(folder.rglob("*.mcap")):
        for _schema, channel, message in RecordingScan(path).messages():
            parts = channel.topic.split("/", 2)
            if len(parts) != 3 or parts[2].startswith("raw"):
                continue
            body = json.loads(message.data)
            run_id = body.get("run_id") if isinstance(body, dict) else None
            if not run_id:  # none, or 0: a restarted acquisition's samples before it knows the run
                continue
            record = runs[parts[1]][run_id]
            record.topics[parts[2]] += 1
            if parts[2] == "samples":
                record.samples[body["sequence"]] += 1
                record.files.add(path)
            elif parts[2] == "runs":
                record.summary = body
    return runs


def station_files(tmp_path: Path) -> list[Path]:
    # the spool on the station's own box (its folder), not in the line's recordings
    return line_station_files(tmp_path, STATIONS, '\n[spool]\nfolder = "{folder}/spool"\n')


def drained(status: dict[str, dict[str, Any]]) -> bool:
    """No run and no sample of any station waits in its spool (what waits is the last
    seconds' counters, not acknowledged yet), and the recorder misses no sample."""
    for index in range(1, STATIONS + 1):
        view = status.get(f"st{index}", {})
        spools, recorder = view.get("spools") or [], view.get("recorder") or {}
        if not spools or any(spool["runs"] or spool["samples"] for spool in spools):
            return False
        if any((spool["oldest_age_s"] or 0.0) > 10.0 for spool in spools):
            return False
        if recorder.get("missing_samples") != 0:
            return False
    return True


def test_cables_cut_and_the_recorder_killed_lose_nothing(tmp_path: Path) -> None:
    files = station_files(tmp_path)
    logs = tmp_path / "logs"
    logs.mkdir()
    processes: dict[str, subprocess.Popen[bytes]] = {}

    def start(line: Line, namespace: str, name: str, args: list[str]) -> None:
        processes[name] = line.boltwatch(namespace, args, logs / f"{name}.log")

    def start_recorder(line: Line) -> None:
        config_all = [str(path) for path in files]
        start(line, line.server, "recorder", ["serve", "recorder", "--config", *config_all])

    status: dict[str, dict[str, Any]] = {}
    with Line(STATIONS) as line:
        try:
            start(line, line.server, "router", ["serve", "router", "--listen", ENDPOINT])
            start_recorder(line)
            for index, path in enumerate(files, start=1):
                args = ["serve", "acquisition", "--config", str(path)]
                start(line, line.station(index), f"st{index}-acquisition", args)
            wait_until_up(line, STATIONS, ("acquisition", "recorder"))
            for index, path in enumerate(files, start=1):
                args = ["serve", "rig", "--config", str(path), "--runs", str(RUNS)]
                start(line, line.station(index), f"st{index}-rig", args)
            time.sleep(5.0)

            for index in (2, 3):  # 1. two cables out; station 2's acquisition restarted
                line.cut(index)
            time.sleep(CUT_S / 2)
            stop_process(processes["st2-acquisition"])
            args = ["serve", "acquisition", "--config", str(files[1])]
            start(line, line.station(2), "st2-acquisition", args)
            time.sleep(CUT_S / 2)
            for index in (2, 3):
                line.reconnect(index)
            time.sleep(10.0)

            processes["recorder"].send_signal(signal.SIGKILL)  # 2. the recorder killed
            processes["recorder"].wait(10)
            time.sleep(CUT_S)
            start_recorder(line)

            for index in range(1, STATIONS + 1):
                rig = processes[f"st{index}-rig"]
                assert rig.wait(300) == 0, f"st{index}'s rig failed; see {logs}"
            deadline = time.monotonic() + 120
            while not drained(status) and time.monotonic() < deadline:
                time.sleep(1.0)
                status = line_status(line)
        finally:
            for process in reversed(processes.values()):
                stop_process(process)
    assert drained(status), json.dumps(status, indent=1)[:4000]

    recordings = read_recordings(tmp_path / "recordings")
    with sqlite3.connect(ledger_path(tmp_path / "recordings")) as ledger:
        counted = Counter(ledger.execute("SELECT station FROM runs").fetchall())
    for index in range(1, STATIONS + 1):
        station = f"st{index}"
        check_station(station, recordings[station], counted[(station,)], cut_off=index == 2)
    with sqlite3.connect(tmp_path / "recordings" / "results.sqlite") as store:
        parts = store.execute(
            "SELECT station, part_id, part_source FROM tightenings ORDER BY station, run_id"
        ).fetchall()
    for index in range(1, STATIONS + 1):
        check_parts(f"st{index}", [(p, s) for st, p, s in parts if st == f"st{index}"], index == 2)


def check_parts(station: str, parts: list[tuple[str | None, str]], cut_off: bool) -> None:
    """Each result says where its part came from. The station whose acquisition restarted
    while its cable was out names no part (``unknown``) until the line answers when its
    cable is back (``restored``), then the next scan's (``scanned``): in that order, never
    back; the others name the parts their line scanned."""
    assert all((part_id is None) == (source == "unknown") for part_id, source in parts), parts
    sources = [source for _, source in parts]
    if not cut_off:
        assert set(sources) == {"scanned"}, f"{station}: {Counter(sources)}"
        return
    # before the restart every part was scanned; from the first run that names none (or the
    # line's) on, it goes one way: unknown, restored, scanned
    restart = next((i for i, source in enumerate(sources) if source != "scanned"), len(sources))
    order = {"unknown": 0, "restored": 1, "scanned": 2}
    ranks = [order[source] for source in sources[restart:]]
    assert ranks == sorted(ranks), f"{station}: {sources}"


def check_station(station: str, runs: dict[int, RunRecord], counted: int, cut_off: bool) -> None:
    """Every run of ``station`` whole; its runs each counted once in the wear ledger.
    ``cut_off``: its acquisition was restarted while its cable was out."""
    # the run station 2's acquisition was in when it was stopped ends there (its samples
    # up to the stop, no summary: faults table, "acquisition killed mid-run"); a restart
    # slower than that run's rest and the pause after it comes up inside the next run,
    # whose start it never heard (its `done` state only, no summary): the two are adjacent
    cut_short = sorted(run_id for run_id, record in runs.items() if record.summary is None)
    assert len(cut_short) <= (2 if cut_off else 0), f"{station}: no summary {cut_short}"
    if cut_short:
        adjacent = list(range(cut_short[0], cut_short[0] + len(cut_short)))
        assert cut_short == adjacent, f"{station}: runs with no summary apart: {cut_short}"
    assert len(runs) - len(cut_short) >= RUNS - (3 if cut_off else 0), (
        f"{station}: {len(runs)} runs recorded"
    )
    twice: list[int] = []  # runs with a message filed again after the recorder was killed
    for run_id, record in runs.items():
        where = f"{station} run {run_id}"
        if max(record.samples.values(), default=1) > 1 or record.topics["decision"] > 1:
            twice.append(run_id)
        if record.summary is None:
            assert sorted(record.samples) == list(range(len(record.samples))), where
            continue
        count = record.summary["samples"]
        assert sorted(record.samples) == list(range(count)), f"{where}: samples missing"
        assert record.topics["results"] >= 1, where
        assert record.topics["events"] >= record.summary["events"], where
        assert record.topics["tool"] >= 2, f"{where}: tool states {record.topics}"
    assert counted == len(runs) - len(cut_short), f"{station}: the wear ledger's runs"
    # what the killed recorder had filed and not acknowledged, sent again: not filed again
    assert twice == [], f"{station}: filed twice: {twice}"
