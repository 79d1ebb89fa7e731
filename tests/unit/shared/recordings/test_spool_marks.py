"""The spool numbers a recording file holds, said last in each chunk and read back: of a
complete file through its index, of a file a kill cut short only as far as its chunks are
whole; a payload put on the marks' key by anyone else is never read as marks."""

from __future__ import annotations

from pathlib import Path

from shared.contract import encode
from shared.recordings import classify
from shared.recordings.mcap import FileMarks, McapSink, filed_in, recover
from shared.spool import SeqRanges
from tests.support import factories

T0_NS = 1_700_000_000_000_000_000


def write_sample(sink: McapSink, seq: int) -> None:
    """Spool message ``seq`` (a sample) into ``sink``, marked as the recorder marks it."""
    sample = factories.sample(1, seq, time_ns=T0_NS + seq)
    sink.write(classify("boltwatch/st1/samples", encode(sample), T0_NS + seq))
    assert sink.marks is not None
    sink.marks.add("acquisition", 77, seq)


def test_the_numbers_a_file_holds_are_read_back_as_far_as_its_chunks_are_whole(
    tmp_path: Path,
) -> None:
    sink = McapSink(tmp_path / "run.mcap", {}, 1, T0_NS)
    sink.marks = FileMarks("st1")
    for seq in (1, 2, 3):
        write_sample(sink, seq)
    forged = encode(factories.sample(1, 9, time_ns=T0_NS))  # anyone may put on that key
    sink.write(classify("boltwatch/st1/spool/filed", forged, T0_NS + 4))
    sink.flush()
    killed = tmp_path / "killed.mcap"
    killed.write_bytes((tmp_path / "run.mcap").read_bytes())  # what a kill leaves now
    for seq in (4, 6):
        write_sample(sink, seq)
    with killed.open("ab") as handle:  # the next chunk, cut short
        handle.write((tmp_path / "run.mcap").read_bytes()[killed.stat().st_size :][:40])
    sink.close()

    assert filed_in(tmp_path / "run.mcap") == {
        ("st1", "acquisition", 77): SeqRanges([(1, 4), (6, 6)])
    }
    recovered = recover(killed, tmp_path / "recovered.mcap")
    assert not recovered.was_complete
    assert filed_in(tmp_path / "recovered.mcap") == {
        ("st1", "acquisition", 77): SeqRanges([(1, 3)])
    }


def test_a_file_with_no_marks_holds_nothing_of_a_spool(tmp_path: Path) -> None:
    sink = McapSink(tmp_path / "run.mcap", {}, 1, T0_NS)
    sink.write(classify("boltwatch/st1/samples", encode(factories.sample(1, 0)), T0_NS))
    sink.close()
    assert filed_in(tmp_path / "run.mcap") == {}
    (tmp_path / "broken.mcap").write_bytes(b"not mcap")
    assert filed_in(tmp_path / "broken.mcap") == {}
