"""classify(): what the recorder files each received payload as.

Flat messages go through the checking codec.decoder: a payload that breaks
its schema (a wrong type, an unknown field) is still recorded, on a raw
channel (``decodable`` False), never silently on the schema'd one.
"""

from __future__ import annotations

import dataclasses
import json
import math
from typing import Any

from shared.contract import (
    Intensity,
    SampleBatch,
    StickSlipEvent,
    ToolState,
    channels,
    encode,
    to_dict,
)
from shared.recordings import MAX_AHEAD_S, OTHER_STATION, classify
from tests.support import factories
from tests.support.fuzz.payloads import template

T_NS = 1_700_000_000_000_000_000
SAMPLE = factories.sample(
    9, 33, station="st4", time_ns=T_NS + 5, torque_nm=80.0, angle_deg=12.5, force_n=None
)


def test_a_sample_is_filed_by_station_run_sequence_and_its_own_time() -> None:
    received = classify(channels.SAMPLES.key("st4"), encode(SAMPLE), T_NS + 99)
    assert received.station == "st4" and received.schema_name == "boltwatch.Sample"
    assert received.message == SAMPLE and received.decodable
    assert (received.run_id, received.sequence) == (9, 33)
    assert (received.log_time_ns, received.publish_time_ns) == (T_NS + 99, T_NS + 5)
    assert not received.run_started


def test_a_sample_breaking_its_schema_is_kept_raw() -> None:
    for change in ({"sequence": "33"}, {"torque_nm": None}, {"extra": 1}):
        payload = json.dumps({**to_dict(SAMPLE), **change}).encode()
        received = classify(channels.SAMPLES.key("st4"), payload, T_NS)
        assert received.schema_name == "boltwatch.Sample"
        assert received.message is None and not received.decodable
        assert received.payload == payload and received.publish_time_ns == T_NS
        assert received.sequence is None


def test_run_start_summary_and_nested_events() -> None:
    running = classify(
        channels.TOOL.key("st4"),
        encode(ToolState("st4", 9, 1, 2, "running", T_NS + 1)),
        T_NS,
    )
    assert running.run_started and running.publish_time_ns == T_NS + 1
    summary = factories.summary(9, station="st4", started_ns=6, ended_ns=7)
    filed = classify(channels.RUNS.key("st4"), encode(summary), T_NS)
    assert filed.message == summary and filed.publish_time_ns == 7  # ended_ns
    event = factories.event(9, 1, station="st4", time_ns=T_NS + 3)
    nested = classify(channels.EVENTS.key("st4"), encode(event), T_NS)
    assert nested.message == event and nested.run_id == 9


def test_other_keys_are_raw() -> None:
    unknown_topic = classify("boltwatch/st4/something", b"\x00", T_NS)
    assert unknown_topic.schema_name is None and unknown_topic.decodable
    assert unknown_topic.station == "st4"
    outside = classify("elsewhere", b"{}", T_NS)
    assert outside.station == OTHER_STATION and outside.schema_name is None


def test_a_batch_is_refused_for_its_first_bad_sample_named_by_index() -> None:
    """A batch's samples are checked as samples that came alone; the first bad one refuses
    the batch (kept raw) and is named in the problem."""
    key = channels.SAMPLE_BATCHES.key("st4")
    good = [dataclasses.replace(SAMPLE, sequence=n, time_ns=T_NS + n) for n in range(5)]
    received = classify(key, encode(SampleBatch("st4", T_NS + 9, good)), T_NS + 99)
    assert received.decodable and received.message.samples == good
    ahead_ns = T_NS + 99 + (MAX_AHEAD_S + 1) * 1_000_000_000
    bad_samples: dict[str, dict[str, Any]] = {
        "it names station 'st5', in a batch of its own": {"station": "st5"},
        f"its time is {MAX_AHEAD_S + 1} s ahead of its arrival": {"time_ns": ahead_ns},
        "torque_nm nan is outside the sensor's": {"torque_nm": math.nan},
        "angle_deg 1e+300 is outside the sensor's": {"angle_deg": 1e300},
        "force_n -1e+300 is outside the sensor's": {"force_n": -1e300},
    }
    for problem, change in bad_samples.items():
        samples = [*good[:3], dataclasses.replace(good[3], **change), good[4]]
        received = classify(key, encode(SampleBatch("st4", T_NS + 9, samples)), T_NS + 99)
        assert received.message is None and not received.decodable
        assert received.problem is not None
        assert received.problem.startswith(f"samples[3]: {problem}"), received.problem


def test_a_batch_is_refused_for_an_event_or_intensity_not_its_own_or_ahead() -> None:
    """The events and intensities a batch carries are checked as those that came alone."""
    key = channels.SAMPLE_BATCHES.key("st4")
    samples = [dataclasses.replace(SAMPLE, sequence=n, time_ns=T_NS + n) for n in range(3)]
    event: StickSlipEvent = template("events", "st4", T_NS + 2, 9)
    figures: Intensity = template("intensity", "st4", T_NS + 2, 9)
    good = SampleBatch("st4", T_NS + 9, samples, [event], [figures])
    received = classify(key, encode(good), T_NS + 99)
    assert received.decodable and received.message == good
    ahead_ns = T_NS + 99 + (MAX_AHEAD_S + 1) * 1_000_000_000
    bad = {
        "events[0]: it names station 'st5'": dataclasses.replace(good, events=[
            dataclasses.replace(event, station="st5")]),
        f"intensities[0]: its time is {MAX_AHEAD_S + 1} s ahead": dataclasses.replace(
            good, intensities=[dataclasses.replace(figures, time_ns=ahead_ns)]),
    }  # fmt: skip
    for problem, batch in bad.items():
        received = classify(key, encode(batch), T_NS + 99)
        assert received.message is None and received.problem is not None
        assert received.problem.startswith(problem), received.problem
