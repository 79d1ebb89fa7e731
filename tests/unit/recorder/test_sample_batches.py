"""An edge station's samples in batches are recorded exactly as samples that came alone.

A real :class:`RecorderService` in a thread (conftest), fed over real zenoh
on loopback. Station ``st1`` publishes each sample as its own message (as a
line-placed station does); station ``st2`` publishes the same run through a
real :class:`QueuedPublisher` with ``batch_samples`` (as an edge station's
acquisition does): both MCAP files must hold the same messages, channel for
channel, with the same sequence, publish time and payload, one MCAP message
per sample. A batch that never arrives is its samples missing, counted end
to end (``RecorderStats.missing_samples``), and so is a batch the recorder
refuses (recorded raw, byte for byte, and counted as a bad payload).
"""

from __future__ import annotations

import dataclasses
import itertools
import json
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import zenoh
from mcap.reader import make_reader
from pydantic import TypeAdapter

from services.recorder.live.incoming import Received
from services.recorder.live.sample_batches import BatchSamples, sample_texts
from services.recorder.mcap_files.mcap_sink import RAW_ENCODING
from shared import channels
from shared.codec import decode, encode
from shared.config import LoadedStation, load_station
from shared.messages import BusStats, RecorderStats, Sample, SampleBatch, ToolState
from shared.queued_publisher import QueuedPublisher
from tests.live_recorder import RunningRecorder, publish, wait_until, write_station_file

RUN = 11
SAMPLES = 400
MS_NS = 1_000_000


@pytest.fixture
def recorder(station: LoadedStation, tmp_path: Path, endpoint: str) -> Iterator[RunningRecorder]:
    """A recorder of st1 (one message per sample) and st2 (batches): it records only the
    stations it has a file for."""
    st2_file = write_station_file(
        tmp_path / "st2.toml", station.recordings_folder, connect=[endpoint]
    )
    st2_file.write_text(st2_file.read_text().replace('id = "st1"', 'id = "st2"'))
    running = RunningRecorder([station, load_station(st2_file)])
    try:
        yield running
    finally:
        running.finish()


def run_of(station: str, t0_ns: int) -> list[tuple[str, Any]]:
    """A run as its acquisition publishes it: running, samples 1 ms apart, done."""
    samples = [
        (
            channels.SAMPLES.topic,
            Sample(station, RUN, n, t0_ns + n * MS_NS, 5.0 + n, 0.2 * n, 1e4 + n, n / 1e3),
        )
        for n in range(SAMPLES)
    ]
    ended_ns = t0_ns + SAMPLES * MS_NS
    return [
        (channels.TOOL.topic, ToolState(station, RUN, 7, 1, "running", t0_ns)),
        *samples,
        (channels.TOOL.topic, ToolState(station, RUN, 7, 1, "done", ended_ns)),
    ]


def read_messages(path: Path) -> list[dict[str, Any]]:
    """Every message of an MCAP file in file order, with its channel and schema."""
    out = []
    with path.open("rb") as handle:
        for schema, channel, message in make_reader(handle).iter_messages(log_time_order=False):
            out.append(
                {
                    "topic": channel.topic,
                    "encoding": channel.message_encoding,
                    "schema": (schema.name, schema.data) if schema else None,
                    "sequence": message.sequence,
                    "publish_time": message.publish_time,
                    "log_time": message.log_time,
                    "data": message.data,
                }
            )
    return out


def files_of(loaded: LoadedStation, station: str) -> list[Path]:
    return sorted(loaded.recordings_folder.glob(f"{station}/*/*.mcap"))


def test_batches_are_recorded_exactly_as_samples_that_came_alone(
    station: LoadedStation, recorder: RunningRecorder, publisher_session: zenoh.Session
) -> None:
    t0_ns = time.time_ns() - 2 * SAMPLES * MS_NS  # stamped as a live station stamps
    alone = publish(publisher_session, run_of("st1", t0_ns))
    batched = QueuedPublisher(publisher_session, "st2", batch_samples=True)
    for topic, message in run_of("st2", t0_ns):
        batched.publish(message)
        if topic == channels.SAMPLES.topic:
            time.sleep(0.0002)  # a live station's pace, roughly: batches of several samples
    batched.close()
    assert batched.failed == batched.dropped == 0
    wait_until(lambda: recorder.service.recorder.messages == 2 * alone, "both runs recorded")
    recorder.finish()

    (file1,) = files_of(station, "st1")
    (file2,) = files_of(station, "st2")
    assert f"_run{RUN}_" in file1.name and f"_run{RUN}_" in file2.name  # one file, the run's
    first, second = read_messages(file1), read_messages(file2)
    assert len(first) == len(second) == alone  # one MCAP message per sample, none twice
    for one, two in zip(first, second, strict=True):
        assert two["topic"] == one["topic"].replace("st1", "st2")
        assert two["data"] == one["data"].replace(b'"st1"', b'"st2"')
        assert (two["encoding"], two["schema"]) == (one["encoding"], one["schema"])
        assert (two["sequence"], two["publish_time"]) == (one["sequence"], one["publish_time"])
    samples = [m for m in second if m["topic"] == "boltwatch/st2/samples"]
    assert [m["sequence"] for m in samples] == list(range(SAMPLES))
    assert {m["schema"][0] for m in samples} == {"boltwatch.Sample"}
    # log times: each sample's arrival, 1 ms apart as on the CAN bus, never before its time
    assert all(m["log_time"] >= m["publish_time"] for m in samples)
    log_steps = {b["log_time"] - a["log_time"] for a, b in itertools.pairwise(samples)}
    assert min(log_steps) >= 0
    assert MS_NS in log_steps  # within a batch, exactly the samples' spacing
    assert recorder.service.recorder.refused["st2"] == 0


def bus(station: str, published: int, started_ns: int) -> BusStats:
    stats = BusStats(station, time.time_ns(), 0, published, *[0] * 11)
    return dataclasses.replace(stats, started_ns=started_ns)


def stats_of(recorder: RunningRecorder, station: str) -> RecorderStats:
    (stats,) = [s for s in recorder.service.stats(time.time_ns()) if s.station == station]
    return stats


def test_a_lost_batch_and_a_refused_one_are_their_samples_missing(
    station: LoadedStation, recorder: RunningRecorder, publisher_session: zenoh.Session
) -> None:
    t0_ns = time.time_ns() - 1000 * MS_NS
    samples = [Sample("st1", RUN, n, t0_ns + n * MS_NS, 5.0, 0.1, 1e4) for n in range(100)]
    batches = [samples[i : i + 10] for i in range(0, 100, 10)]
    refused = [*batches[7][:-1], Sample("st1", RUN, 79, t0_ns + 79 * MS_NS, 1e9, 0.1, 1e4)]
    refused_payload = encode(SampleBatch("st1", t0_ns + 80 * MS_NS, refused))
    started_ns = t0_ns - 1000 * MS_NS
    items: list[tuple[str, Any]] = [
        (channels.BUS.topic, bus("st1", 0, started_ns)),  # counting starts here
        (channels.TOOL.topic, ToolState("st1", RUN, 7, 1, "running", t0_ns)),
    ]
    for index, batch in enumerate(batches):
        if index == 3:
            continue  # lost on the way: never arrives
        if index == 7:
            items.append((channels.SAMPLE_BATCHES.topic, refused_payload))
            continue
        items.append((channels.SAMPLE_BATCHES.topic, SampleBatch("st1", batch[-1].time_ns, batch)))
    items.append((channels.BUS.topic, bus("st1", 100, started_ns)))  # the acquisition published 100
    publish(publisher_session, items)
    written = 2 + 80 + 1 + 1  # bus, tool, 8 batches of 10 samples, the refused batch, bus
    wait_until(lambda: recorder.service.recorder.messages == written, "everything recorded")
    stats = stats_of(recorder, "st1")
    assert stats.missing_samples == 20  # the lost batch and the refused one
    assert stats.bad_payloads == 1
    recorder.finish()

    messages = [m for path in files_of(station, "st1") for m in read_messages(path)]
    sequences = [
        json.loads(m["data"])["sequence"] for m in messages if m["topic"].endswith("/samples")
    ]
    assert sequences == [n for n in range(100) if not 30 <= n < 40 and not 70 <= n < 80]
    raw = [m for m in messages if m["topic"] == "boltwatch/st1/sample_batches"]
    assert [(m["encoding"], m["data"]) for m in raw] == [(RAW_ENCODING, refused_payload)]


def batch_of(station: str, count: int) -> SampleBatch:
    t0_ns = 1_700_000_000_000_000_000
    samples = [
        Sample(station, RUN, n, t0_ns + n * MS_NS, 5.0 + n / 3, 0.2 * n, None if n % 2 else 1e4)
        for n in range(count)
    ]
    return SampleBatch(station, t0_ns + count * MS_NS, samples)


@pytest.mark.parametrize("count", [1, 2, 10])
def test_a_compact_batch_gives_each_sample_as_the_station_wrote_it(count: int) -> None:
    batch = batch_of("line-7_b", count)
    assert sample_texts(encode(batch), batch) == [encode(s) for s in batch.samples]


def test_a_batch_in_another_form_is_encoded_again() -> None:
    batch = batch_of("st1", 3)
    spaced = json.dumps(dataclasses.asdict(batch)).encode()  # ", " and ": " between items
    as_dict = dataclasses.asdict(batch)
    reordered = json.dumps(dict(reversed(as_dict.items())), separators=(",", ":")).encode()
    for payload in (spaced, reordered):
        assert decode(SampleBatch, payload) == batch
        assert sample_texts(payload, batch) is None
    samples = BatchSamples().samples(received_batch(spaced, batch))
    assert [s.payload for s in samples] == [encode(s) for s in batch.samples]


def test_a_batch_with_two_lists_of_samples_is_encoded_again() -> None:
    """The decoder takes the last of two ``samples`` keys; a list of one sample before a
    list of two has as many pieces between braces as there are samples, not the samples."""
    first, *rest = batch_of("st1", 3).samples
    one = encode(SampleBatch("st1", first.time_ns, [first]))
    twice = one[:-1] + b',"samples":' + TypeAdapter(list[Sample]).dump_json(rest) + b"}"
    batch = decode(SampleBatch, twice)
    assert batch.samples == rest
    assert sample_texts(twice, batch) is None


def received_batch(payload: bytes, batch: SampleBatch) -> Received:
    key = channels.SAMPLE_BATCHES.key(batch.station)
    arrival_ns = batch.time_ns + MS_NS
    return Received(
        key,
        batch.station,
        channels.SAMPLE_BATCHES.schema_name,
        batch,
        payload,
        arrival_ns,
        batch.time_ns,
    )
