"""A line predictor keeps what it puts toward the line in a spool, as every station service does.

Over real zenoh on loopback: a router (a session in router mode), the line's
recorder, a line predictor (``placement = "line"``) for pt1, and pt1's
acquisition (its samples and tool states through a spooling publisher, one
message per sample, as a line-placed station sends them). The recorder is
stopped while pt1 tightens two runs and a half, then started again. Afterwards
every event, intensity, decision, result and summary the predictor put (as a
live subscriber heard them) is in the recordings exactly once, in a file of its
own run, and every run's samples are whole in one file.
"""

from __future__ import annotations

import json
import threading
from collections import Counter
from pathlib import Path
from typing import Any

import pytest
import zenoh
from mcap.reader import make_reader

from services.predictor.service import PredictorService
from shared.config import LoadedStation, load_station
from shared.contract import Sample, SpoolStats, ToolState, channels, to_dict
from shared.runtime import QueuedPublisher, ServiceSkeleton, zenoh_config
from shared.spool import SpoolFile, StationSpool
from tests.support.listener import Listener
from tests.support.live_predictor import START_NS, station_text, wait_for_token
from tests.support.live_recorder import RunningRecorder, wait_until
from tests.support.synthetic_runs import staircase

S = 1_000_000_000
ROWS = staircase().rows()  # a whole run: events, then a decision
#: what the line predictor puts for each run
PREDICTOR_TOPICS = (
    channels.EVENTS.topic,
    channels.INTENSITY.topic,
    channels.DECISION.topic,
    channels.RESULTS.topic,
    channels.RUNS.topic,
)
FAST_SPOOL = """
[spool]
resend_after_s = 0.5
drain_messages_per_s = 2000.0
"""
DRAIN_S = 60.0


@pytest.fixture
def endpoint(router_endpoint: str) -> str:
    """The line's router (the services are its clients)."""
    return router_endpoint


@pytest.fixture
def station(tmp_path: Path, endpoint: str) -> LoadedStation:
    text = station_text(tmp_path, "pt1", 1, endpoint, connect=True, extra=FAST_SPOOL)
    path = tmp_path / "pt1.toml"
    path.write_text(text.replace("[predictor]\n", '[predictor]\nplacement = "line"\n'))
    return load_station(path)


class Acquisition:
    """pt1's acquisition, placement line: each sample and tool state through a spooling
    publisher, as the service puts them."""

    def __init__(self, session: zenoh.Session, folder: Path) -> None:
        self.spool = StationSpool(
            "pt1",
            "acquisition",
            SpoolFile(folder / "pt1-acquisition.sqlite"),
            1 << 30,
            drain_messages_per_s=4000.0,
            resend_after_s=0.5,
        )
        self.publisher = QueuedPublisher(session, "pt1", spool=self.spool)

    def run(self, run_id: int) -> None:
        at_ns = START_NS + run_id * 10 * S
        publish = self.publisher.publish
        publish(ToolState("pt1", run_id, 3, 1, "running", at_ns))
        for sequence, (t, torque, force, angle) in enumerate(ROWS):
            time_ns = at_ns + round(t * 1e9)
            publish(Sample("pt1", run_id, sequence, time_ns, torque, angle, force, t))
        publish(ToolState("pt1", run_id, 3, 1, "done", at_ns + 2 * S, "plateau_closest"))
        self.flushed()

    def flushed(self) -> None:
        """Once everything queued has been put."""
        done = threading.Event()
        self.publisher.call(done.set)
        wait_until(done.is_set, "the acquisition's puts")

    def close(self) -> None:
        self.publisher.close()


def spool_of(heard: Listener, source: str) -> list[SpoolStats]:
    return [stats for stats in heard.of(channels.SPOOL.topic) if stats.source == source]


def wait_for_drain(heard: Listener, source: str) -> None:
    """Until a spool counter of ``source`` heard after now says that nothing put before it
    waits any more (what waits then is the last second's counters)."""
    seen = len(spool_of(heard, source))
    heard.wait(lambda: len(spool_of(heard, source)) > seen, f"the {source}'s spool counters")
    head = spool_of(heard, source)[-1].head_seq

    def drained() -> bool:
        latest = spool_of(heard, source)[-1]
        return latest.messages == 0 or latest.oldest_seq > head

    heard.wait(drained, f"the {source}'s spool drained", DRAIN_S)


def recorded(station: LoadedStation) -> dict[Path, list[tuple[str, dict[str, Any]]]]:
    """(topic, message) of every file of pt1, in file order."""
    files = {}
    for path in sorted(station.recordings_folder.glob("pt1/*/*.mcap")):
        with path.open("rb") as handle:
            files[path] = [
                (channel.topic.split("/", 2)[2], json.loads(message.data))
                for _schema, channel, message in make_reader(handle).iter_messages()
            ]
    return files


def canonical(topic: str, message: dict[str, Any]) -> tuple[str, str]:
    return topic, json.dumps(message, sort_keys=True)


def runs_of(messages: Counter[tuple[str, str]]) -> Counter[tuple[str, int]]:
    """How many of ``messages`` per (topic, run id)."""
    counted: Counter[tuple[str, int]] = Counter()
    for (topic, text), times in messages.items():
        counted[(topic, json.loads(text)["run_id"])] += times
    return counted


def test_what_a_line_predictor_put_while_the_recorder_was_down_is_recorded_once(
    tmp_path: Path, endpoint: str, station: LoadedStation
) -> None:
    skeleton = ServiceSkeleton("predictor")
    skeleton.open_session(station.config.zenoh)
    predictor = PredictorService(skeleton, [station])
    stop = threading.Event()
    worker = threading.Thread(target=predictor.work, args=(stop,), daemon=True)
    worker.start()
    session = zenoh.open(zenoh_config("client", connect=[endpoint]))
    heard = Listener(session, "pt1", (*PREDICTOR_TOPICS, channels.SPOOL.topic))
    wait_for_token(session, "boltwatch/pt1/health/predictor")
    # a spooling acquisition reaches the line as a peer connected to its router only
    box = zenoh.open(zenoh_config("peer", connect=[endpoint], connect_only=True))
    acquisition = Acquisition(box, tmp_path / "edge")
    recorder = RunningRecorder(station)
    try:
        wait_for_token(session, "boltwatch/pt1/health/recorder")
        acquisition.run(1)
        heard.wait_for(channels.RUNS.topic, 1)
        recorder.finish()  # the line's recorder is down while runs 2 and 3 are tightened
        acquisition.run(2)
        acquisition.run(3)
        heard.wait_for(channels.RUNS.topic, 3)
        recorder = RunningRecorder(station)  # back: both spools send again what it lacks
        acquisition.run(4)
        heard.wait_for(channels.RUNS.topic, 4)
        wait_for_drain(heard, "predictor")
        wait_for_drain(heard, "acquisition")
    finally:
        recorder.finish()
        acquisition.close()
        stop.set()
        predictor.wake()
        worker.join(10.0)
        skeleton.close()
        heard.close()
        box.close()
        session.close()
    assert not worker.is_alive()

    put = Counter(
        canonical(topic, to_dict(message))
        for topic in PREDICTOR_TOPICS
        for message in heard.of(topic)
    )
    assert len(heard.of(channels.DECISION.topic)) == 4 and len(heard.of(channels.EVENTS.topic)) > 4
    files = recorded(station)
    kept = Counter(
        canonical(topic, message)
        for messages in files.values()
        for topic, message in messages
        if topic in PREDICTOR_TOPICS
    )
    assert kept == put, f"lost: {runs_of(put - kept)}, twice: {runs_of(kept - put)}"
    for path, messages in files.items():
        for topic, message in messages:
            if topic in PREDICTOR_TOPICS:
                assert f"_run{message['run_id']}_" in path.name, f"{topic} in {path.name}"
    for run_id in (1, 2, 3, 4):
        (path,) = [
            path
            for path, messages in files.items()
            if any(t == "samples" and m["run_id"] == run_id for t, m in messages)
        ]
        samples = [m["sequence"] for t, m in files[path] if t == "samples"]
        assert samples == list(range(len(ROWS))), f"run {run_id}: samples lost or out of order"
