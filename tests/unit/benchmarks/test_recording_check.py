"""The stress benchmark's check finds each wrong payload, sample twice and sample missing."""

from __future__ import annotations

import time
from pathlib import Path

from shared.contract import Sample, encode
from shared.recordings import classify
from shared.recordings.mcap import McapSink
from tests.benchmarks.recording_check import check_recordings

T0_NS = time.time_ns() - 10**9


def sample(run_id: int, sequence: int, station: str = "st1") -> bytes:
    return encode(Sample(station, run_id, sequence, T0_NS + sequence, 10.0, 1.0, 20_000.0))


def write(path: Path, payloads: list[tuple[str, bytes]]) -> None:
    with McapSink(path, {}, 7, T0_NS) as sink:
        for key, payload in payloads:
            sink.write(classify(key, payload, T0_NS + 10**6))


def test_a_whole_recording_passes(tmp_path: Path) -> None:
    write(tmp_path / "st1" / "a.mcap", [("boltwatch/st1/samples", sample(7, n)) for n in range(5)])
    check = check_recordings(tmp_path, {"st1": {7: 5}})
    assert check.ok and check.summary()["missing_samples"] == 0
    assert (check.samples, check.messages, check.files) == (5, 5, 1)


def test_garbled_twice_missing_and_unfinished_are_each_found(tmp_path: Path) -> None:
    garbled = b'{"s' + bytes(range(14)) + sample(7, 3)  # the start of one and the whole of the next
    write(
        tmp_path / "st1" / "a.mcap",
        [
            ("boltwatch/st1/samples", sample(7, 0)),
            ("boltwatch/st1/samples", garbled),  # refused by the recorder: its raw channel
            ("boltwatch/st1/samples", sample(7, 1)),
            ("boltwatch/st1/samples", sample(7, 1)),  # twice
            ("boltwatch/st1/samples", sample(8, 0)),  # a run st1 never published
        ],
    )
    (tmp_path / "st1" / ".b.mcap.writing").write_bytes(b"")
    check = check_recordings(tmp_path, {"st1": {7: 4}})
    summary = check.summary()
    assert not check.ok
    assert summary["bad_messages"] == 1 and "raw channel" in str(summary["bad_examples"])
    assert (check.duplicates, check.unexpected, check.unfinished) == (1, 1, 1)
    assert summary["missing_by_station"] == {"st1": 2}  # sequences 2 and 3 of run 7
