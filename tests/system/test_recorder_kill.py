"""The recorder as a real process: kill -9 loses at most about a flush interval and leaves no
broken file under a run file's name; SIGTERM nothing; kill -9 while results arrive: the
restarted recorder finishes what the killed one left, and the results store and the
recordings agree.

``boltwatch serve recorder`` runs as a subprocess (a zenoh peer listening on
a free loopback port); this test publishes a run at ~1 kHz into it.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import threading
import time
from collections import Counter
from collections.abc import Iterator
from pathlib import Path

import pytest
import zenoh
from mcap.reader import make_reader

from shared.contract import (
    Sample,
    SpoolAck,
    SpoolStats,
    TighteningResult,
    ToolState,
    channels,
    decode,
    encode,
    keys,
)
from shared.recordings import final_path_of, unfinished_files
from shared.recordings.mcap import RecordingScan, recover
from shared.results import ResultsQuery, ResultsStore, StoreTarget
from shared.runtime import QueuedPublisher, zenoh_config
from shared.spool import SpoolFile, StationSpool
from tests.support import factories
from tests.support.listener import Listener
from tests.support.live_recorder import (
    free_port,
    has_subscribers,
    wait_until,
    write_station_file,
)
from tests.support.paths import REPO
from tests.support.recorded_runs import run_messages

pytestmark = pytest.mark.system

RATE_HZ = 1000
PUBLISH_S = 3.0
FLUSH_INTERVAL_S = 1.0


class RecorderProcess:
    def __init__(
        self,
        tmp_path: Path,
        log_name: str = "recorder.log",
        flush_interval_s: float = FLUSH_INTERVAL_S,
        endpoint: str | None = None,
    ) -> None:
        self.endpoint = endpoint or f"tcp/127.0.0.1:{free_port()}"
        self.recordings = tmp_path / "recordings"
        station_file = write_station_file(
            tmp_path / "station.toml",
            self.recordings,
            listen=[self.endpoint],
            recorder={"flush_interval_s": flush_interval_s},
        )
        self.log = (tmp_path / log_name).open("w")
        self.process = subprocess.Popen(
            [sys.executable, "-m", "services.cli", "serve", "recorder", "--config", station_file],
            cwd=REPO,
            stdout=self.log,
            stderr=subprocess.STDOUT,
        )

    def files(self) -> list[Path]:
        return sorted(self.recordings.glob("st1/*/*.mcap"))

    def unfinished(self) -> list[Path]:
        """Files under their writing name: being written, or left by a kill."""
        return unfinished_files(self.recordings)

    def stop(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
        self.process.wait(10)
        self.log.close()


@pytest.fixture
def recorder_process(tmp_path: Path) -> Iterator[RecorderProcess]:
    running = RecorderProcess(tmp_path)
    try:
        yield running
    finally:
        running.stop()


@pytest.fixture
def session(recorder_process: RecorderProcess) -> Iterator[zenoh.Session]:
    opened = zenoh.open(zenoh_config("peer", connect=[recorder_process.endpoint]))
    try:
        yield opened
    finally:
        opened.close()


def publish_run(session: zenoh.Session, run_id: int, duration_s: float) -> int:
    """ToolState running, then samples at ~RATE_HZ for ``duration_s``; the sample count."""
    tool = session.declare_publisher(channels.TOOL.key("st1"))
    samples = session.declare_publisher(channels.SAMPLES.key("st1"))
    publishers = (tool, samples)
    wait_until(lambda: all(has_subscribers(p) for p in publishers), "the recorder")
    tool.put(encode(ToolState("st1", run_id, 7, 1, "running", time.time_ns())))
    total = round(duration_s * RATE_HZ)
    start = time.monotonic()
    for n in range(total):
        if n % 10 == 0:  # pace in bursts of 10 samples every 10 ms
            time.sleep(max(0.0, start + n / RATE_HZ - time.monotonic()))
        samples.put(encode(Sample("st1", run_id, n, time.time_ns(), 1.0 + n, 0.1 * n, 2.0 * n)))
    tool.undeclare()
    samples.undeclare()
    return total


def recorded_sequences(scan: RecordingScan) -> list[int]:
    return [message.sequence for _, _, message in scan.messages("/samples")]


def test_kill_9_loses_at_most_about_one_flush_interval(
    recorder_process: RecorderProcess, session: zenoh.Session, tmp_path: Path
) -> None:
    sent = publish_run(session, run_id=1, duration_s=PUBLISH_S)
    recorder_process.process.send_signal(signal.SIGKILL)
    recorder_process.process.wait(10)

    assert recorder_process.files() == []  # no run file's name on a broken file
    (killed,) = recorder_process.unfinished()
    report = recover(killed, tmp_path / "recovered.mcap")
    assert not report.was_complete
    with (tmp_path / "recovered.mcap").open("rb") as handle:
        reader = make_reader(handle)
        got = [
            m.sequence
            for _, c, m in reader.iter_messages(log_time_order=False)
            if c.topic.endswith("/samples")
        ]
    missing = sent - len(got)
    print(f"kill -9: sent {sent}, recovered {len(got)}, lost {missing} from the tail")
    assert got == list(range(len(got)))  # a gap-free prefix of what was sent
    # At most the unflushed chunk (≤ one flush interval) plus what was still in flight.
    assert missing <= FLUSH_INTERVAL_S * RATE_HZ * 1.5
    assert len(got) > 0


def test_sigterm_leaves_a_complete_file(
    recorder_process: RecorderProcess, session: zenoh.Session
) -> None:
    sent = publish_run(session, run_id=2, duration_s=0.5)

    def everything_flushed() -> bool:
        files = recorder_process.unfinished()  # being written
        return len(files) == 1 and len(recorded_sequences(RecordingScan(files[0]))) == sent

    wait_until(everything_flushed, "the recorder to flush every sample")
    recorder_process.process.send_signal(signal.SIGTERM)
    assert recorder_process.process.wait(10) == 0

    (path,) = recorder_process.files()
    assert recorder_process.unfinished() == []
    with path.open("rb") as handle:
        reader = make_reader(handle)
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None
        sample_channels = [c.id for c in summary.channels.values() if c.topic.endswith("/samples")]
        assert summary.statistics.channel_message_counts[sample_channels[0]] == sent
    scan = RecordingScan(path)
    assert len(recorded_sequences(scan)) == sent and scan.complete
    verify = [str(Path(sys.executable).parent / "rerun"), "rrd", "verify"]
    assert subprocess.run([*verify, str(path.with_suffix(".rrd"))], check=False).returncode == 0


def publish_results(session: zenoh.Session, runs: range, stop: threading.Event) -> None:
    """Short runs, each ended by its result, until ``stop`` (the recorder killed)."""
    tool = session.declare_publisher(channels.TOOL.key("st1"))
    results = session.declare_publisher(channels.RESULTS.key("st1"))
    wait_until(lambda: has_subscribers(tool) and has_subscribers(results), "the recorder")
    for run_id in runs:
        if stop.is_set():
            break
        now_ns = time.time_ns()
        tool.put(encode(ToolState("st1", run_id, 7, 1, "running", now_ns)))
        tool.put(encode(ToolState("st1", run_id, 7, 1, "done", now_ns + 1000)))
        results.put(encode(factories.result(run_id, time_ns=now_ns + 2000, part_id=f"P{run_id}")))
        time.sleep(0.02)
    tool.undeclare()
    results.undeclare()


def recorded_results(recordings: Path) -> dict[int, TighteningResult]:
    """Every result in the recordings by run, files left by a kill read as far as they go."""
    return {
        result.run_id: result
        for path in sorted([*recordings.glob("st1/*/*.mcap"), *unfinished_files(recordings)])
        for _, _, message in RecordingScan(path).messages("/results")
        for result in [decode(TighteningResult, message.data)]
    }


def stored_results(recordings: Path) -> dict[int, TighteningResult]:
    target = StoreTarget(sqlite_path=recordings / "results.sqlite")
    try:
        with ResultsStore(target, create=False) as store:
            found = store.find(ResultsQuery(limit=None))
    except Exception:  # not made yet
        return {}
    return {stored.result.run_id: stored.result for stored in found}


def test_kill_9_while_results_arrive_then_the_store_and_the_recordings_agree(
    recorder_process: RecorderProcess, session: zenoh.Session, tmp_path: Path
) -> None:
    stop = threading.Event()
    publisher = threading.Thread(target=publish_results, args=(session, range(1, 400), stop))
    publisher.start()
    try:
        wait_until(lambda: len(stored_results(recorder_process.recordings)) >= 20, "20 stored")
        recorder_process.process.send_signal(signal.SIGKILL)
        recorder_process.process.wait(10)
    finally:
        stop.set()
        publisher.join()
    killed_store = stored_results(recorder_process.recordings)
    recorded = recorded_results(recorder_process.recordings)
    left = recorder_process.unfinished()  # the files open when it was killed (a run's, and
    assert left  # the one before it within its late grace)
    # a file killed before its first flush holds no message: the next recorder removes it
    holding = [path for path in left if next(RecordingScan(path).messages(), None)]
    assert all(scan_complete(path) for path in recorder_process.files())  # only whole files
    assert killed_store.items() <= recorded.items()  # a result stored is in a file on disk
    print(f"kill -9: {len(recorded)} results recorded, {len(killed_store)} stored")

    restarted = RecorderProcess(tmp_path, log_name="restarted.log")
    try:
        wait_until(
            lambda: stored_results(restarted.recordings) == recorded,
            "the restarted recorder to store what the killed one had not",
            30.0,
        )
        # the restarted recorder finished what the killed one left, under its run file's name
        wait_until(lambda: restarted.unfinished() == [], "the killed recorder's file finished")
        assert {final_path_of(path) for path in holding} <= set(restarted.files())
        assert all(scan_complete(path) for path in restarted.files())
    finally:
        restarted.stop()
    assert recorded_results(restarted.recordings) == recorded
    assert "finished under their names" in (tmp_path / "restarted.log").read_text()


def scan_complete(path: Path) -> bool:
    scan = RecordingScan(path)
    for _ in scan.records():
        pass
    return scan.complete


def test_kill_9_while_a_spooling_station_publishes_files_every_sample_exactly_once(
    tmp_path: Path,
) -> None:
    """A station spooling what it puts (an edge station's batches) publishes runs while the
    line's recorder is killed with SIGKILL and started again. The killed recorder had
    flushed more than it had acknowledged (it flushes every 0.2 s here, acknowledges once a
    second): the station sends that again, and the restarted recorder, which finished the
    killed one's files, recognises it. Every sample of every run is in exactly one file."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    recorder = RecorderProcess(tmp_path, flush_interval_s=0.2, endpoint=endpoint)
    session = zenoh.open(zenoh_config("peer", connect=[endpoint]))
    spool = StationSpool(
        "st1",
        "acquisition",
        SpoolFile(tmp_path / "edge" / "st1-acquisition.sqlite"),
        1 << 30,
        drain_messages_per_s=500.0,
        resend_after_s=0.5,
    )
    publisher = QueuedPublisher(session, "st1", batch_samples=True, spool=spool)
    heard = Listener(session, topics=[channels.SPOOL.topic, channels.SPOOL_ACK.topic])
    published: list[tuple[int, int]] = []
    stop = threading.Event()

    def tighten() -> None:
        run_id = 0
        while not stop.is_set():
            run_id += 1
            for topic, message in run_messages(run_id, 400):
                publisher.publish(message)
                if topic == "samples":
                    published.append((run_id, message.sequence))
                    if message.sequence % 10 == 0:
                        time.sleep(0.01)  # about 1 kHz

    station = threading.Thread(target=tighten)
    try:
        wait_until(lambda: recorder_alive(session), "the recorder", timeout_s=30)
        station.start()
        wait_until(lambda: len(published) > 2500, "runs published")

        def between_acknowledgements() -> bool:  # flushed twice since the last one
            acks: list[SpoolAck] = heard.of(channels.SPOOL_ACK.topic)
            return bool(acks) and 0.5e9 <= time.time_ns() - acks[-1].time_ns <= 0.8e9

        wait_until(between_acknowledgements, "0.5 s after an acknowledgement")
        recorder.process.send_signal(signal.SIGKILL)  # mid-run
        recorder.process.wait(10)
        wait_until(lambda: len(published) > 3500, "runs published with no recorder")
        recorder = RecorderProcess(
            tmp_path, flush_interval_s=0.2, endpoint=endpoint, log_name="restarted.log"
        )
        wait_until(lambda: len(published) > 6000, "runs published to the restarted recorder")
        stop.set()
        station.join()
        done = threading.Event()
        publisher.call(done.set)
        wait_until(done.is_set, "the station's puts")
        head_seq = spool.stats().head_seq

        def emptied() -> bool:
            spools: list[SpoolStats] = heard.of(channels.SPOOL.topic)
            return bool(spools) and spools[-1].head_seq >= head_seq and spools[-1].messages == 0

        wait_until(emptied, "the spool emptied", timeout_s=60)
        recorder.process.send_signal(signal.SIGTERM)
        assert recorder.process.wait(10) == 0
    finally:
        stop.set()
        if station.is_alive():
            station.join()
        recorder.stop()
        publisher.close()
        heard.close()
        session.close()
    times: Counter[tuple[int, int]] = Counter()
    for path in recorder.files():
        for _, _, message in RecordingScan(path).messages("/samples"):
            times[(json.loads(message.data)["run_id"], message.sequence)] += 1
    twice = sorted(key for key, count in times.items() if count > 1)
    assert not twice, f"{len(twice)} samples in two files, e.g. {twice[:5]}"
    assert set(times) == set(published), "a sample lost"


def recorder_alive(session: zenoh.Session) -> bool:
    replies = session.liveliness().get(keys.health_key("st1", "recorder"), timeout=1)
    return any(reply.ok is not None for reply in replies)
