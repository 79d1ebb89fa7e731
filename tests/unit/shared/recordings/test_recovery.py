"""Recovery of truncated recordings: every complete chunk back, a valid file out."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest
from mcap.reader import make_reader

from shared.contract import Sample, encode
from shared.errors import InputError
from shared.recordings import classify
from shared.recordings.mcap import McapSink, RecordingScan, default_target, recover

T0_NS = 1_700_000_000_000_000_000


@pytest.fixture
def sink(tmp_path: Path) -> Iterator[McapSink]:
    with McapSink(tmp_path / "live.mcap", {"station": {"station": "st1"}}, 1, T0_NS) as sink:
        yield sink


def write_samples(sink: McapSink, first: int, count: int) -> None:
    for n in range(first, first + count):
        payload = encode(Sample("st1", 1, n, T0_NS + n, 1.0, 2.0, 3.0))
        sink.write(classify("boltwatch/st1/samples", payload, T0_NS + n + 10))


def snapshot(sink: McapSink, to: Path, keep_bytes: int | None = None) -> Path:
    """The bytes on disk right now, as a kill -9 would leave them (or their first bytes)."""
    shutil.copyfile(sink.path, to)
    if keep_bytes is not None:
        with to.open("r+b") as handle:
            handle.truncate(keep_bytes)
    return to


def sequences(path: Path) -> list[int]:
    with path.open("rb") as handle:
        reader = make_reader(handle)
        assert reader.get_summary() is not None  # a valid, indexed file
        return [m.sequence for _, _, m in reader.iter_messages(log_time_order=False)]


def test_unflushed_messages_are_all_that_is_lost(sink: McapSink, tmp_path: Path) -> None:
    write_samples(sink, 0, 100)
    sink.flush()
    write_samples(sink, 100, 100)
    sink.flush()
    write_samples(sink, 200, 50)  # still in the open chunk
    killed = snapshot(sink, tmp_path / "killed.mcap")
    report = recover(killed)
    assert report.target == default_target(killed) == tmp_path / "killed.recovered.mcap"
    assert not report.was_complete
    assert report.messages == 200
    assert sequences(report.target) == list(range(200))
    with report.target.open("rb") as handle:
        metadata = {m.name: m.metadata for m in make_reader(handle).iter_metadata()}
    assert metadata == {"station": {"station": "st1"}}


def test_a_half_written_chunk_is_left_out(sink: McapSink, tmp_path: Path) -> None:
    write_samples(sink, 0, 100)
    sink.flush()
    first_chunk_end = sink.path.stat().st_size
    write_samples(sink, 100, 100)
    sink.flush()
    killed = snapshot(sink, tmp_path / "killed.mcap", keep_bytes=first_chunk_end + 40)
    report = recover(killed, tmp_path / "out.mcap")
    assert report.damage is not None
    assert sequences(tmp_path / "out.mcap") == list(range(100))


def test_a_complete_file_is_copied_whole(sink: McapSink, tmp_path: Path) -> None:
    write_samples(sink, 0, 30)
    sink.close()
    report = recover(sink.path, tmp_path / "copy.mcap")
    assert report.was_complete
    assert sequences(tmp_path / "copy.mcap") == list(range(30))
    scan = RecordingScan(sink.path)
    assert len(list(scan.messages("/samples"))) == 30
    assert scan.complete
    assert scan.describe().endswith("complete")


def test_not_an_mcap_file_is_an_input_error(tmp_path: Path) -> None:
    bogus = tmp_path / "bogus.mcap"
    bogus.write_bytes(b"time_s,torque_nm\n")
    with pytest.raises(InputError, match=r"bogus\.mcap: not an MCAP file"):
        recover(bogus)
    assert not default_target(bogus).exists()
    with pytest.raises(InputError, match="file not found"):
        recover(tmp_path / "missing.mcap")
    empty = tmp_path / "empty.mcap"
    empty.touch()
    with pytest.raises(InputError, match="empty"):
        recover(empty)
