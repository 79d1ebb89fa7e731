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

from services.recorder.live.sample_batches import BatchSamples, sample_texts
from shared.config import LoadedStation, load_station
from shared.contract import (
    BusStats,
    Intensity,
    RecorderStats,
    Sample,
    SampleBatch,
    ToolState,
    channels,
    decode,
    encode,
)
from shared.recordings import Received
from shared.recordings.mcap import RAW_ENCODING
from shared.runtime import QueuedPublisher
from tests.support.fuzz.payloads import template
from tests.support.live_recorder import RunningRecorder, publish, wait_until, write_station_file

RUN = 11
SAMPLES = 400
MS_NS = 1_000_000
#: an event every 20 samples: one in five lands on a batch's 50th sample, the batch goes
#: full with it and the event goes alone after it; the others ride in a batch
EVENT_EVERY = 20


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


def found_at(station: str, index: int, sample: Sample) -> list[tuple[str, Any]]:
    """The event the edge predictor finds at ``sample`` and its intensity, as it publishes
    them (right after the sample)."""
    intensity = 0.1 * index
    event = dataclasses.replace(
        template("events", station, sample.time_ns, RUN),
        index=index,
        time_s=sample.time_s or 0.0,
        peak_torque_nm=sample.torque_nm,
        intensity=intensity,
        process_intensity=intensity * (index + 1) / 2,
    )
    figures = Intensity(station, RUN, sample.time_ns, intensity, event.process_intensity)
    return [(channels.EVENTS.topic, event), (channels.INTENSITY.topic, figures)]


def run_of(station: str, t0_ns: int) -> list[tuple[str, Any]]:
    """A run as its edge station publishes it: running, samples 1 ms apart with an event and
    its intensity every EVENT_EVERY samples, done."""
    published: list[tuple[str, Any]] = [
        (channels.TOOL.topic, ToolState(station, RUN, 7, 1, "running", t0_ns))
    ]
    for n in range(SAMPLES):
        sample = Sample(station, RUN, n, t0_ns + n * MS_NS, 5.0 + n, 0.2 * n, 1e4 + n, n / 1e3)
        published.append((channels.SAMPLES.topic, sample))
        if n % EVENT_EVERY == EVENT_EVERY - 1:
            published += found_at(station, n // EVENT_EVERY + 1, sample)
    ended_ns = t0_ns + SAMPLES * MS_NS
    return [*published, (channels.TOOL.topic, ToolState(station, RUN, 7, 1, "done", ended_ns))]


def by_topic(messages: list[dict[str, Any]]) -> dict[str, list[dict[str, Any]]]:
    grouped: dict[str, list[dict[str, Any]]] = {}
    for message in messages:
        grouped.setdefault(message["topic"].split("/", 2)[2], []).append(message)
    return grouped


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
    heard: list[tuple[str, bytes]] = []
    listeners = [
        publisher_session.declare_subscriber(
            channel.key("st2"), lambda s: heard.append((str(s.key_expr), s.payload.to_bytes()))
        )
        for channel in (channels.SAMPLE_BATCHES, channels.EVENTS)
    ]
    batched = QueuedPublisher(publisher_session, "st2", batch_samples=True)
    for topic, message in run_of("st2", t0_ns):
        batched.publish(message)
        if topic == channels.SAMPLES.topic:
            time.sleep(0.0002)  # a live station's pace, roughly: batches of several samples
    batched.close()
    assert batched.failed == batched.dropped == 0

    def events_heard() -> tuple[int, int]:
        """(events in batches, events alone) heard on zenoh so far."""
        batches = [decode(SampleBatch, p) for k, p in list(heard) if "batches" in k]
        alone = sum(k.endswith("/events") for k, _ in list(heard))
        return sum(len(b.events) for b in batches), alone

    wait_until(lambda: sum(events_heard()) == SAMPLES // EVENT_EVERY, "every event on zenoh")
    in_batches, events_alone = events_heard()
    assert in_batches > events_alone  # most ride in a batch; the rest came just after one
    for listener in listeners:
        listener.undeclare()
    wait_until(lambda: recorder.service.recorder.messages == 2 * alone, "both runs recorded")
    recorder.finish()

    (file1,) = files_of(station, "st1")
    (file2,) = files_of(station, "st2")
    assert f"_run{RUN}_" in file1.name and f"_run{RUN}_" in file2.name  # one file, the run's
    first, second = read_messages(file1), read_messages(file2)
    assert len(first) == len(second) == alone  # one MCAP message per sample, none twice
    # channel for channel the same messages in the same order (across channels, a batch's
    # events are filed after its samples: after the sample each was found at, as alone)
    alone_by_topic, batched_by_topic = by_topic(first), by_topic(second)
    assert set(batched_by_topic) == {"tool", "samples", "events", "intensity"}
    for topic, ones in alone_by_topic.items():
        for one, two in zip(ones, batched_by_topic[topic], strict=True):
            assert two["topic"] == one["topic"].replace("st1", "st2")
            assert two["data"] == one["data"].replace(b'"st1"', b'"st2"')
            assert (two["encoding"], two["schema"]) == (one["encoding"], one["schema"])
            assert (two["sequence"], two["publish_time"]) == (one["sequence"], one["publish_time"])
    filed_at = {(m["topic"], m["publish_time"]): i for i, m in enumerate(second)}
    for event in batched_by_topic["events"]:
        peak_sample = filed_at[("boltwatch/st2/samples", event["publish_time"])]
        assert filed_at[("boltwatch/st2/events", event["publish_time"])] > peak_sample
    samples = batched_by_topic["samples"]
    assert [m["sequence"] for m in samples] == list(range(SAMPLES))
    assert {m["schema"][0] for m in samples} == {"boltwatch.Sample"}
    # log times: each sample's arrival, 1 ms apart as on the CAN bus, never before its time
    assert all(m["log_time"] >= m["publish_time"] for m in samples)
    log_steps = {b["log_time"] - a["log_time"] for a, b in itertools.pairwise(samples)}
    assert min(log_steps) >= 0
    assert MS_NS in log_steps  # within a batch, exactly the samples' spacing
    assert recorder.service.recorder.refused["st2"] == 0


def bus(station: str, published: int, started_ns: int) -> BusStats:
    stats = BusStats(station, time.time_ns(), 0, published, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0)
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


def test_a_batch_with_events_gives_its_samples_as_written_and_its_events_alone() -> None:
    batch = batch_of("st1", 10)
    found = [*found_at("st1", 1, batch.samples[4]), *found_at("st1", 2, batch.samples[9])]
    events = [message for topic, message in found if topic == channels.EVENTS.topic]
    intensities = [message for topic, message in found if topic == channels.INTENSITY.topic]
    full = dataclasses.replace(batch, events=events, intensities=intensities)
    payload = encode(full)
    assert sample_texts(payload, full) == [encode(s) for s in batch.samples]
    filed = BatchSamples().found(received_batch(payload, full))
    assert [(r.key, r.schema_name, r.payload, r.publish_time_ns) for r in filed] == [
        (channel.key("st1"), channel.schema_name, encode(m), m.time_ns)
        for channel, m in [(channels.EVENTS, e) for e in events]
        + [(channels.INTENSITY, i) for i in intensities]
    ]
    arrival_ns = received_batch(payload, full).log_time_ns
    assert {r.log_time_ns for r in filed} == {arrival_ns}


def test_a_second_samples_key_after_the_events_is_encoded_again() -> None:
    """Behind the events, a second ``samples`` key (plain or spelled with an escape) is the
    list the decoder keeps: the first list's pieces are not the samples."""
    first, *rest = batch_of("st1", 3).samples
    one = encode(SampleBatch("st1", first.time_ns, [first, first]))
    for name in (b'"samples"', b'"sampl\\u0065s"'):
        twice = one[:-1] + b"," + name + b":" + TypeAdapter(list[Sample]).dump_json(rest) + b"}"
        batch = decode(SampleBatch, twice)
        assert batch.samples == rest
        assert sample_texts(twice, batch) is None
