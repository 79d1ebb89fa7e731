"""A run file under its writing name until complete; what a crash left, finished under its name.

The bytes a kill leaves are those the sink flushed: copied from the writing
file while the sink is open (a real kill of the recorder is
``tests/system/test_recorder_kill.py``).
"""

from __future__ import annotations

import shutil
from pathlib import Path

from shared.contract import Sample, encode
from shared.recordings import (
    classify,
    file_name_of,
    file_path,
    recording_files,
    run_files,
    unfinished_files,
    writing_path,
)
from shared.recordings.mcap import McapSink, RecordingScan, finish_unfinished

T0_NS = 1_700_000_000_000_000_000


def run_sink(folder: Path, run_id: int) -> McapSink:
    path = file_path(folder, "st1", run_id, T0_NS + run_id * 10**9)
    return McapSink(path, {"station": {"station": "st1"}}, run_id, T0_NS, rename_when_complete=True)


def write_samples(sink: McapSink, count: int) -> None:
    for n in range(count):
        payload = encode(Sample("st1", sink.run_id or 0, n, T0_NS + n, 1.0, 2.0, 3.0))
        sink.write(classify("boltwatch/st1/samples", payload, T0_NS + n + 10))


def left_by_a_kill(sink: McapSink, folder: Path) -> Path:
    """The writing file as a kill -9 leaves it (what was flushed), the sink let go."""
    copy = folder / "kept"
    shutil.copyfile(sink.writing_path, copy)
    sink.abandon()
    shutil.move(copy, sink.writing_path)
    return sink.writing_path


def test_a_run_file_has_its_name_only_once_complete_and_no_reader_takes_it_before(
    tmp_path: Path,
) -> None:
    sink = run_sink(tmp_path, 3)
    write_samples(sink, 100)
    sink.flush()
    day = sink.path.parent
    assert not sink.path.exists() and sink.writing_path.is_file()
    assert recording_files(day) == [] and run_files(tmp_path, "st1", 3) == []
    assert list(tmp_path.rglob("*.mcap")) == []  # readers that glob run files never meet it
    assert file_name_of(sink.writing_path, "st1") is None
    assert unfinished_files(tmp_path) == [sink.writing_path]
    # a name being written is taken: a second file of the same second is a copy
    second = file_path(tmp_path, "st1", 3, T0_NS + 3 * 10**9)
    assert second.name.endswith("_2.mcap")
    sink.close()
    assert not sink.writing_path.exists()
    assert run_files(tmp_path, "st1", 3) == [sink.path]
    scan = RecordingScan(sink.path)
    assert sum(1 for _ in scan.messages()) == 100 and scan.complete


def test_what_a_crash_left_is_finished_under_the_run_files_names(tmp_path: Path) -> None:
    cut = run_sink(tmp_path, 1)  # killed mid-run: flushed samples, no footer
    write_samples(cut, 500)
    cut.flush()
    write_samples(cut, 50)  # not flushed: lost with the kill
    left_by_a_kill(cut, tmp_path)
    empty = run_sink(tmp_path, 2)  # killed before its first flush reached the disk
    empty.abandon()
    writing_path(empty.path).write_bytes(b"")
    whole = run_sink(tmp_path, 4)  # killed between its finish and its rename
    write_samples(whole, 20)
    whole.close()
    whole.path.rename(writing_path(whole.path))
    foreign = writing_path(file_path(tmp_path, "st1", 5, T0_NS))
    foreign.write_bytes(b"not an mcap file at all")

    done = finish_unfinished(tmp_path)

    assert unfinished_files(tmp_path) == [foreign]  # unreadable: left, and named
    assert (done.finished, done.messages) == (2, 520)
    (left,) = done.left
    assert left.writing == foreign and left.problem is not None
    (recovered,) = run_files(tmp_path, "st1", 1)
    scan = RecordingScan(recovered)
    assert [m.sequence for _, _, m in scan.messages("/samples")] == list(range(500))
    assert scan.complete and recovered == cut.path
    assert run_files(tmp_path, "st1", 2) == []  # it held nothing: removed
    (renamed,) = run_files(tmp_path, "st1", 4)
    assert sum(1 for _ in RecordingScan(renamed).messages()) == 20
    assert not any(p.name.endswith(".recovering") for p in tmp_path.rglob("*"))
    assert finish_unfinished(tmp_path).finished == 0  # a second start finds nothing more


def test_a_file_already_under_the_name_is_never_replaced(tmp_path: Path) -> None:
    sink = run_sink(tmp_path, 1)
    write_samples(sink, 10)
    sink.flush()
    left_by_a_kill(sink, tmp_path)
    sink.path.write_bytes(b"someone's own copy")
    (done,) = finish_unfinished(tmp_path).files
    assert sink.path.read_bytes() == b"someone's own copy"
    assert done.final is not None and done.final.name.endswith(".recovered.mcap")
    assert run_files(tmp_path, "st1", 1) == sorted([sink.path, done.final])
