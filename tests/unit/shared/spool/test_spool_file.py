"""The spool on disk: numbers never given twice, what was committed survives a killed
process, what waits is counted."""

from __future__ import annotations

import os
import sqlite3
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from shared.spool import SeqRanges, SpoolFile
from shared.spool.spool_file import COMMIT_ROWS, KIND_OTHER, KIND_RECORDS, KIND_SAMPLES
from tests.support.disk_faults import fill_up, tmpfs
from tests.support.paths import REPO


def fill(spool: SpoolFile, kinds: str, run_id: int = 1) -> list[int]:
    """One message per letter: s (a batch of 10 samples), r (a record), o (another)."""
    kind = {"s": KIND_SAMPLES, "r": KIND_RECORDS, "o": KIND_OTHER}
    seqs = []
    for n, letter in enumerate(kinds):
        samples = 10 if letter == "s" else 0
        payload = f'{{"n": {n}, "kind": "{letter}"}}'.encode() * 20
        seqs.append(spool.append("samples", payload, kind[letter], run_id, samples, 1000 + n))
    spool.commit()
    return seqs


def test_numbers_count_from_one_and_are_never_given_twice(tmp_path: Path) -> None:
    path = tmp_path / "st1-acquisition.sqlite"
    spool = SpoolFile(path)
    spool_id = spool.spool_id
    assert fill(spool, "sso") == [1, 2, 3]
    spool.delete([(1, 3)])  # all of it acknowledged
    spool.close()
    again = SpoolFile(path)
    assert again.spool_id == spool_id  # the same spool: its numbers go on
    assert again.head_seq == 3
    assert fill(again, "s") == [4]
    again.close()
    other = SpoolFile(tmp_path / "elsewhere.sqlite")
    assert other.spool_id != spool_id  # a spool made again says so: its numbers restart
    assert fill(other, "s") == [1]
    other.close()


def test_what_waits_is_counted_and_found_again_after_a_restart(tmp_path: Path) -> None:
    path = tmp_path / "spool.sqlite"
    spool = SpoolFile(path)
    fill(spool, "sssor", run_id=4)
    fill(spool, "so", run_id=5)
    spool.delete([(2, 3)])
    depth = spool.depth()
    assert (depth.messages, depth.samples, depth.runs, depth.oldest_seq) == (5, 20, 2, 1)
    assert depth.oldest_run_id == 4 and depth.oldest_ns == 1000
    spool.close()
    reopened = SpoolFile(path)
    assert reopened.depth().messages == 5 and reopened.depth().samples == 20
    assert reopened.stored_bytes == spool.stored_bytes
    reopened.close()


def test_the_oldest_of_a_kind_go_first_and_the_others_stay(tmp_path: Path) -> None:
    spool = SpoolFile(tmp_path / "spool.sqlite")
    fill(spool, "srsosrs")  # 1 s, 2 r, 3 s, 4 o, 5 s, 6 r, 7 s
    assert spool.drop_oldest(KIND_SAMPLES, 2) == (2, 20)
    left = [m.seq for m in spool.after(0, 100, 10**9, SeqRanges())]
    assert left == [2, 4, 5, 6, 7]
    spool.close()


def test_what_is_sent_again_names_the_number_the_spool_holds_before_it(tmp_path: Path) -> None:
    spool = SpoolFile(tmp_path / "spool.sqlite")
    fill(spool, "ssssssss")  # 1..8, put at 1000..1007
    spool.delete([(2, 3)])
    spool.drop_oldest(KIND_SAMPLES, 0)
    found = spool.after(0, 3, 1006, SeqRanges([(5, 5)]))
    assert [(m.seq, m.kept_before) for m in found] == [(1, 0), (4, 1), (6, 5)]
    assert found[0].payload.startswith(b'{"n": 0')  # as it was put (stored compressed)
    # the pass stops at the first message not old enough; never past it
    assert [m.seq for m in spool.after(6, 10, 1006, SeqRanges())] == []
    assert [(m.seq, m.kept_before) for m in spool.after(6, 10, 2000, SeqRanges())] == [
        (7, 6),
        (8, 7),
    ]
    spool.close()


def test_a_killed_process_loses_only_what_it_had_not_committed(tmp_path: Path) -> None:
    path = tmp_path / "spool.sqlite"
    script = textwrap.dedent(
        f"""
        import os
        from pathlib import Path
        from shared.spool import SpoolFile
        spool = SpoolFile(Path({str(path)!r}))
        for n in range(5):
            spool.append("tool", b"kept", 2, 1, 0, n)
        spool.commit()
        for n in range(3):
            spool.append("tool", b"in flight", 2, 1, 0, n)
        os._exit(0)  # killed: no close, no commit
        """
    )
    subprocess.run([sys.executable, "-c", script], cwd=REPO, check=True, timeout=60)
    spool = SpoolFile(path)
    assert [m.payload for m in spool.after(0, 100, 10**9, SeqRanges())] == [b"kept"] * 5
    assert spool.depth().messages == 5
    # the numbers the killed process gave may have gone out with their messages: skipped
    assert spool.skipped_at_open == COMMIT_ROWS
    assert spool.append("tool", b"next", 2, 1, 0, 9) == 5 + COMMIT_ROWS + 1
    spool.close()
    assert SpoolFile(path).skipped_at_open == 0  # closed cleanly: nothing skipped


def test_a_full_disk_loses_the_group_in_progress_and_the_spool_works_again_with_room(
    tmp_path: Path,
) -> None:
    """A real full disk (a tmpfs filled up) fails the group being written: SQLite rolls it
    back. Its numbers (already put toward the line) are never given again, what is kept is
    counted again from the file, and once there is room the spool keeps messages again."""
    with tmpfs(tmp_path / "edge", 1 << 20) as edge:
        spool = SpoolFile(edge / "st1-acquisition.sqlite")
        kept = fill(spool, "sr", run_id=1)
        assert kept == [1, 2]
        filler = fill_up(edge)
        given: list[int] = []
        with pytest.raises(sqlite3.OperationalError):
            for n in range(5000):  # the group's pages spill to the full disk, or its commit
                given.append(spool.append("samples", os.urandom(300), KIND_SAMPLES, 2, 10, n))
            spool.commit()
        assert given  # put toward the line with these numbers: lost with the group
        assert (spool.messages, spool.samples, spool.depth().runs) == (2, 10, 1)
        spool.commit()  # nothing in progress: no error
        filler.unlink()
        after = fill(spool, "so", run_id=3)
        assert after[0] > max(given)  # never a number given before
        assert spool.messages == 4 and spool.head_seq == after[-1]
        spool.close()
        reopened = SpoolFile(edge / "st1-acquisition.sqlite")
        assert reopened.skipped_at_open == 0  # closed cleanly
        assert [m.seq for m in reopened.after(0, 10, 10**18, SeqRanges())] == [*kept, *after]
        reopened.close()
