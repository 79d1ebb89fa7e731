"""Store and forward over real zenoh: a station's spooling publisher and the line's recorder.

The recorder is stopped while the station goes on (a dead recorder: what the
station puts meanwhile reaches nobody), then started again; the station's
spool sends what the recorder lacks. Afterwards every run is in one file,
whole: every sample once, in order, every event, decision, result, summary
and tool state as it was put (read back from the MCAP files), and the
spool is empty.
"""

from __future__ import annotations

import json
import threading
import time
from collections import defaultdict
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import zenoh
from mcap.reader import make_reader

from shared.config import LoadedStation
from shared.contract import (
    SpoolStats,
    ToolState,
    channels,
    encode,
    keys,
    seq_attachment,
    to_dict,
)
from shared.runtime import QueuedPublisher, zenoh_config
from shared.spool import SpoolFile, StationSpool
from tests.support import factories
from tests.support.listener import Listener
from tests.support.live_recorder import RunningRecorder, has_subscribers, wait_until
from tests.support.recorded_runs import run_messages

SAMPLES = 400  # per run: eight batches of samples


def emptied_through(heard: Listener, head_seq: int) -> bool:
    """The station's spool, as the line hears it, gave ``head_seq`` and holds nothing."""
    spools: list[SpoolStats] = heard.of(channels.SPOOL.topic)
    return bool(spools) and spools[-1].head_seq >= head_seq and spools[-1].messages == 0


@pytest.fixture
def station_session(endpoint: str) -> Iterator[zenoh.Session]:
    session = zenoh.open(zenoh_config("peer", connect=[endpoint]))
    try:
        yield session
    finally:
        session.close()


def read_back(station: LoadedStation) -> dict[Path, list[tuple[str, dict[str, Any]]]]:
    """(topic, message) of every file of st1, in file order."""
    files = {}
    for path in sorted(station.recordings_folder.glob("st1/*/*.mcap")):
        with path.open("rb") as handle:
            files[path] = [
                (channel.topic.split("/", 2)[2], json.loads(message.data))
                for _schema, channel, message in make_reader(handle).iter_messages()
            ]
    return files


@pytest.mark.parametrize("batch_samples", [True, False], ids=["edge", "line"])
def test_a_run_put_while_the_recorder_was_down_is_recorded_whole_once_it_is_back(
    tmp_path: Path, station: LoadedStation, station_session: zenoh.Session, batch_samples: bool
) -> None:
    spool = StationSpool(
        "st1",
        "acquisition",
        SpoolFile(tmp_path / "edge" / "st1-acquisition.sqlite"),
        1 << 30,
        drain_messages_per_s=500.0,
        resend_after_s=0.5,
    )
    publisher = QueuedPublisher(station_session, "st1", batch_samples=batch_samples, spool=spool)
    heard = Listener(station_session, topics=[channels.SPOOL.topic])
    runs = {run_id: run_messages(run_id, SAMPLES) for run_id in (1, 2, 3, 4)}
    put = 0

    def publish(messages: list[tuple[str, Any]]) -> None:
        nonlocal put
        for _topic, message in messages:
            publisher.publish(message)
        publisher.call(lambda: None)
        put += len(messages)

    recorder = RunningRecorder(station)
    try:
        publish(runs[1])
        wait_until(lambda: spool.stats().head_seq > 0 and emptied_through(heard, 1), "run 1 acked")
        recorder.finish()  # the line's recorder is down
        publish(runs[2])
        half = len(runs[3]) // 2
        publish(runs[3][:half])
        stopped = threading.Event()
        publisher.call(stopped.set)
        wait_until(stopped.is_set, "the station's puts")
        recorder = RunningRecorder(station)  # back: the station sends again what it lacks
        publish(runs[3][half:])
        publish(runs[4])
        head = threading.Event()
        publisher.call(head.set)
        wait_until(head.is_set, "the last puts")
        head_seq = spool.stats().head_seq
        wait_until(lambda: emptied_through(heard, head_seq), "the spool emptied", timeout_s=60)
    finally:
        recorder.finish()
        publisher.close()
        heard.close()

    files = read_back(station)
    by_run: dict[int, list[Path]] = defaultdict(list)
    for path, messages in files.items():
        for run_id in {int(m["run_id"]) for _, m in messages if m.get("run_id") is not None}:
            by_run[run_id].append(path)
    assert sorted(by_run) == [1, 2, 3, 4]
    for run_id, published in runs.items():
        (path,) = by_run[run_id]  # one file per run
        recorded = [(t, m) for t, m in files[path] if m.get("run_id") == run_id]
        samples = [m["sequence"] for t, m in recorded if t == "samples"]
        assert samples == list(range(SAMPLES)), f"run {run_id}: samples out of order or lost"
        expected = [(topic, to_dict(message)) for topic, message in published if topic != "samples"]
        others = [(t, m) for t, m in recorded if t != "samples"]
        assert sorted(others, key=repr) == sorted(expected, key=repr), f"run {run_id}"
        published_samples = [to_dict(m) for t, m in published if t == "samples"]
        assert [m for t, m in recorded if t == "samples"] == published_samples
    # what went while the recorder was down came again (run 2 alone is 8 batches and 6 more)
    assert spool.resent >= 14


def test_a_run_whose_start_is_sent_again_is_in_order_by_log_time(
    station: LoadedStation, station_session: zenoh.Session
) -> None:
    """A recorder that came back mid-run missed the run's start (its ToolState and first
    samples): the rest, live, waits in its memory until the station sends the start again.
    The run's one file is in order whichever way it is read, by log time too: what waited
    is logged when it is filed, after what was sent again before it."""
    recorder = RunningRecorder(station)
    numbered = [("tool", ToolState("st1", 4, 7, 1, "running", 1))] + [
        ("samples", factories.sample(4, n, time_ns=10 + n)) for n in range(10)
    ]
    try:
        puts = {
            topic: station_session.declare_publisher(
                keys.station_key("st1", topic), congestion_control=zenoh.CongestionControl.BLOCK
            )
            for topic in ("tool", "samples")
        }
        wait_until(lambda: all(has_subscribers(p) for p in puts.values()), "the recorder")
        for seq, (topic, message) in enumerate(numbered, start=1):
            if seq > 3:  # 1 to 3 (the run's start) were lost on the way
                puts[topic].put(encode(message), attachment=seq_attachment("acquisition", 9, seq))
        time.sleep(0.2)  # the live ones arrived first
        for seq, (topic, message) in enumerate(numbered[:3], start=1):
            station_session.put(
                keys.again_key("st1", topic),
                encode(message),
                attachment=seq_attachment("acquisition", 9, seq, seq - 1),
            )
        wait_until(lambda: recorder.service.recorder.messages == len(numbered), "all filed")
    finally:
        recorder.finish()
    ((path, messages),) = read_back(station).items()
    samples = [m["sequence"] for topic, m in messages if topic == "samples"]
    assert samples == list(range(10)), path  # read back by log time
