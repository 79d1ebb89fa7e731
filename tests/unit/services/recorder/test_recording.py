"""A run published on real zenoh lands in one MCAP file per run, decodable without our code."""

from __future__ import annotations

import contextlib
import json
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
import zenoh
from mcap.decoder import DecoderFactory
from mcap.reader import make_reader
from mcap.records import Schema
from mcap.well_known import MessageEncoding

from services.recorder.service import RecorderService
from shared.config import LoadedStation, load_station
from shared.contract import (
    Sample,
    channels,
    encode,
    json_schema,
    keys,
)
from shared.recordings.mcap import RAW_ENCODING, RAW_REASON, RecordingScan
from shared.runtime import ServiceSkeleton, zenoh_config
from tests.support.live_recorder import (
    RunningRecorder,
    has_subscribers,
    publish,
    wait_until,
    write_station_file,
)
from tests.support.recorded_runs import EVENTS, SAMPLES, recorded_files, run_messages


class JsonDecoderFactory(DecoderFactory):
    """mcap's Python package decodes no JSON by itself: this is the whole of it."""

    def decoder_for(
        self, message_encoding: str, schema: Schema | None
    ) -> Callable[[bytes], Any] | None:
        return json.loads if message_encoding == MessageEncoding.JSON else None


def test_a_run_becomes_one_decodable_mcap_file(
    station: LoadedStation, recorder: RunningRecorder, publisher_session: zenoh.Session
) -> None:
    run1 = run_messages(1, SAMPLES)
    extras: list[tuple[str, Any]] = [("custom", b"\x00\x01raw"), ("events", b"not json")]
    run2 = run_messages(2, 10)
    sent = publish(publisher_session, run1 + extras) + publish(publisher_session, run2)
    wait_until(lambda: recorder.service.recorder.messages == sent, "every message recorded")
    recorder.finish()

    files = recorded_files(station)
    assert [f.name.split("_")[1] for f in files] == ["run1", "run2"]
    rerun_verify = [str(Path(sys.executable).parent / "rerun"), "rrd", "verify"]
    for mcap in files:  # the Rerun recording beside each run file (test_rerun_sink.py)
        rrd = str(mcap.with_suffix(".rrd"))
        assert subprocess.run([*rerun_verify, rrd], check=False).returncode == 0
    assert files[0].parent.name.count("-") == 2  # <YYYY-MM-DD>
    with files[0].open("rb") as handle:
        reader = make_reader(handle, decoder_factories=[JsonDecoderFactory()])
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None
        assert summary.statistics.message_count == len(run1) + len(extras)
        schemas = {schema.name: schema for schema in summary.schemas.values()}
        sample_schema = schemas["boltwatch.Sample"]
        assert sample_schema.encoding == "jsonschema"
        assert json.loads(sample_schema.data) == json_schema(Sample)
        assert set(schemas) == {
            "boltwatch.Sample",
            "boltwatch.ToolState",
            "boltwatch.StickSlipEvent",
            "boltwatch.Intensity",
            "boltwatch.StopDecision",
            "boltwatch.RunSummary",
        }
        channels = {(c.topic, c.message_encoding) for c in summary.channels.values()}
        assert ("boltwatch/st1/samples", "json") in channels
        assert ("boltwatch/st1/custom", RAW_ENCODING) in channels
        raw_reasons = {
            c.topic: c.metadata[RAW_REASON]
            for c in summary.channels.values()
            if c.message_encoding == RAW_ENCODING
        }
        assert raw_reasons == {
            "boltwatch/st1/custom": "unknown key",
            "boltwatch/st1/events": "undecodable",
        }

        samples = [
            (message, data)
            for _, channel, message, data in reader.iter_decoded_messages(
                topics=["boltwatch/st1/samples"], log_time_order=False
            )
        ]
    assert [m.sequence for m, _ in samples] == list(range(SAMPLES))
    assert [m.publish_time for m, _ in samples] == [d["time_ns"] for _, d in samples]
    assert all(m.log_time > m.publish_time for m, _ in samples)  # received after acquisition
    assert samples[0][1]["force_n"] is None and samples[1][1]["force_n"] == 10_001.0

    with files[0].open("rb") as handle:
        metadata = {record.name: record.metadata for record in make_reader(handle).iter_metadata()}
    assert metadata["station"]["station"] == "st1"
    assert metadata["station"]["tool_id"] == "7"
    assert metadata["station"]["software_version"]
    assert metadata["run"] == {"run_id": "1", "tool_id": "7", "program_id": "1"}
    assert metadata["program"]["target_force_n"] == "56000.0"
    assert metadata["joint"]["screw.pitch_mm"] == "1.5"

    with files[0].open("rb") as handle:
        by_topic: dict[str, list[int]] = {}
        for _, channel, message in make_reader(handle).iter_messages(log_time_order=False):
            by_topic.setdefault(channel.topic, []).append(message.sequence)
    assert by_topic["boltwatch/st1/events"][:EVENTS] == list(range(EVENTS))
    assert by_topic["boltwatch/st1/runs"] == [0]

    with files[1].open("rb") as handle:
        summary = make_reader(handle).get_summary()
    assert summary is not None and summary.statistics is not None
    assert summary.statistics.message_count == len(run2)


def test_one_recorder_serves_several_station_files(
    tmp_path: Path, endpoint: str, caplog: pytest.LogCaptureFixture
) -> None:
    """Per-station metadata, wear queryable, health token and RecorderStats; a station
    with no file is not this recorder's (another line's, in a plant): never subscribed to,
    never recorded, not counted anywhere."""
    recordings = tmp_path / "recordings"
    st1 = load_station(write_station_file(tmp_path / "st1.toml", recordings, listen=[endpoint]))
    st2_file = write_station_file(tmp_path / "st2.toml", recordings, connect=[endpoint])
    text = st2_file.read_text().replace('id = "st1"', 'id = "st2"')
    st2_file.write_text(text.replace("tool_id = 7", "tool_id = 8"))
    st2 = load_station(st2_file)
    skeleton = ServiceSkeleton("recorder", zenoh.open(zenoh_config("peer", listen=[endpoint])))
    service = RecorderService([st1, st2], skeleton, rerun_files=False)
    stats: list[dict[str, Any]] = []
    with serving(service, skeleton), zenoh.open(zenoh_config("peer", connect=[endpoint])) as client:
        watcher = client.declare_subscriber(
            channels.RECORDER.key("*"),
            lambda sample: stats.append(json.loads(sample.payload.to_bytes())),
        )
        tokens = client.liveliness().get(keys.health_key("*", "recorder"), timeout=10)
        assert sorted(str(r.ok.key_expr) for r in tokens if r.ok is not None) == [
            "boltwatch/st1/health/recorder",
            "boltwatch/st2/health/recorder",
        ]
        other_line = client.declare_publisher(channels.SAMPLES.key("st3"))
        client.put(f"{keys.ROOT}/not-a-station-key", b"{}")  # no station's: not recorded either
        for topic, message in run_messages(5, 20):
            client.put(keys.station_key("st3", topic), encode(at_station(message, "st3", 9)))
        sent = 0
        for name, tool_id in (("st1", 7), ("st2", 8)):
            items = [(topic, at_station(m, name, tool_id)) for topic, m in run_messages(5, 20)]
            sent += publish(client, items, station=name)
        assert not has_subscribers(other_line)  # the recorder never asked for st3
        wait_until(lambda: service.recorder.messages == sent, "every message recorded")
        per_station = len(run_messages(5, 20))
        wait_until(
            lambda: {s["station"] for s in stats if s["messages"] == per_station} == {"st1", "st2"},
            "RecorderStats counting every message of every station",
        )
        assert {s["station"] for s in stats} == {"st1", "st2"}
        assert all(s["bad_payloads"] == 0 for s in stats)
        with_lag = [s for s in stats if s["lag_p50_ms"] is not None]
        assert {s["station"] for s in with_lag} == {"st1", "st2"}
        assert all(0 < s["lag_p50_ms"] <= s["lag_max_ms"] for s in with_lag)
        assert all(s["recording"] and s["write_errors"] == 0 for s in stats)
        for name, tool_ids in (("st1", [7]), ("st2", [8])):
            (reply,) = client.get(keys.station_key(name, keys.WEAR), timeout=10)
            assert reply.ok is not None
            answer = json.loads(reply.ok.payload.to_bytes())
            assert answer["station"] == name
            assert [tool["tool_id"] for tool in answer["tools"]] == tool_ids
        assert list(client.get(keys.station_key("st3", keys.WEAR), timeout=1)) == []
        watcher.undeclare()

    assert service.recorder.messages == sent  # nothing of st3 came late either
    made = sorted(path.name for path in recordings.iterdir() if "-" not in path.name)
    assert made == ["results.sqlite", "st1", "st2", "wear.sqlite"]  # (and SQLite's -wal, -shm)
    metadata = {}
    for name in ("st1", "st2"):
        (path,) = recordings.glob(f"{name}/*/{name}_run5_*.mcap")
        with path.open("rb") as handle:
            metadata[name] = {r.name: r.metadata for r in make_reader(handle).iter_metadata()}
    assert metadata["st1"]["station"]["tool_id"] == "7"
    assert metadata["st2"]["station"]["tool_id"] == "8"
    assert metadata["st2"]["station"]["station_file"] == str(st2_file)
    assert "joint" in metadata["st2"] and "program" in metadata["st2"]
    assert not [r for r in caplog.records if "st3" in r.getMessage()]


def at_station(message: Any, station: str, tool_id: int) -> Any:
    """``message`` as if sent by ``station`` (with ``tool_id`` where it names the tool)."""
    if hasattr(message, "tool_id"):
        return replace(message, station=station, tool_id=tool_id)
    return replace(message, station=station)


@contextlib.contextmanager
def serving(service: RecorderService, skeleton: ServiceSkeleton) -> Iterator[RecorderService]:
    """The service's worker running; on exit it is stopped, then its skeleton (its
    declarations, then its session)."""
    stop = threading.Event()
    worker = threading.Thread(target=service.work, args=(stop,))
    worker.start()
    try:
        yield service
    finally:
        stop.set()
        service.wake()
        worker.join(10)
        skeleton.close()


def test_a_view_only_recorder_takes_none_of_the_line_recorders_duties(
    tmp_path: Path, endpoint: str
) -> None:
    """docker-compose's viewer: its health token is ``viewer``, it answers no wear query,
    publishes no RecorderStats and keeps no wear ledger, so nothing mistakes it for the
    line's recorder; it still records what it hears (into its own folder)."""
    recordings = tmp_path / "viewer"
    st1 = load_station(write_station_file(tmp_path / "st1.toml", recordings, listen=[endpoint]))
    skeleton = ServiceSkeleton("viewer", zenoh.open(zenoh_config("peer", listen=[endpoint])))
    service = RecorderService(st1, skeleton, rerun_files=False, view_only=True)
    stats: list[bytes] = []
    with serving(service, skeleton), zenoh.open(zenoh_config("peer", connect=[endpoint])) as client:
        watcher = client.declare_subscriber(
            channels.RECORDER.key("*"), lambda sample: stats.append(b"")
        )
        tokens = client.liveliness().get(keys.health_key("st1", "*"), timeout=10)
        assert [str(r.ok.key_expr) for r in tokens if r.ok is not None] == [
            "boltwatch/st1/health/viewer"
        ]
        sent = publish(client, run_messages(5, 20))
        wait_until(lambda: service.recorder.messages == sent, "every message recorded")
        time.sleep(2.5)  # two RecorderStats periods: a line recorder would have published
        assert stats == []
        assert list(client.get(keys.station_key("st1", keys.WEAR), timeout=1)) == []
        watcher.undeclare()
    assert list(recordings.glob("st1/*/st1_run5_*.mcap"))
    assert not (recordings / "wear.sqlite").exists()


def test_the_newest_runs_file_is_final_a_grace_after_its_summary(
    tmp_path: Path,
    station: LoadedStation,
    recorder: RunningRecorder,
    publisher_session: zenoh.Session,
) -> None:
    """One run, then nothing: its file (and its .rrd) take their names a short grace after
    the run's summary, readable, with no next run and the recorder still recording."""
    publish(publisher_session, run_messages(1, SAMPLES))
    wait_until(lambda: recorded_files(station) != [], "run 1's file under its name")
    assert recorder.thread.is_alive()
    (path,) = recorded_files(station)
    assert path.name.startswith("st1_run1_")
    scan = RecordingScan(path)
    assert [message.sequence for _, _, message in scan.messages("/samples")] == list(range(SAMPLES))
    assert scan.complete
    rerun_verify = [str(Path(sys.executable).parent / "rerun"), "rrd", "verify"]
    assert (
        subprocess.run([*rerun_verify, str(path.with_suffix(".rrd"))], check=False).returncode == 0
    )
    inspected = subprocess.run(
        [
            sys.executable,
            "-m",
            "services.cli",
            "inspect",
            str(path),
            "--out",
            str(tmp_path / "run1.png"),
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert inspected.returncode == 0, inspected.stderr
