"""``max_disk_used_pct`` on a real file system: a 20 MB tmpfs holding the recordings (the
store too), filled by run files of 1 MB; the pass measures it with shutil.disk_usage, as the
recorder does, deletes the oldest first, and leaves it at its limit, not below by more than a
file. Mounting needs root: skipped with the reason without it."""

from __future__ import annotations

import shutil
import time
from pathlib import Path
from typing import NamedTuple

from shared.config import RetentionSection
from shared.results import ResultsStore, StoreTarget
from shared.retention import (
    DISK,
    NOT_STORED,
    FileResultsCache,
    RetentionScope,
    delete_planned,
    plan_pass,
)
from tests.support.disk_faults import tmpfs
from tests.support.retention_files import DAY_NS, run_result, store, write_run_file

MB = 1 << 20


class Usage(NamedTuple):
    """What shutil.disk_usage gives."""

    total: int
    used: int
    free: int


def test_past_its_limit_the_oldest_files_go_until_the_disk_is_at_it(tmp_path: Path) -> None:
    with tmpfs(tmp_path / "recordings", 20 * MB) as folder:
        target = StoreTarget(sqlite_path=folder / "results.sqlite")
        now_ns = time.time_ns()
        files = []
        for run_id in range(1, 13):  # oldest first: run 1 was written 13 days ago
            result = run_result(run_id)
            path = write_run_file(
                folder, run_id, now_ns - (14 - run_id) * DAY_NS, [result], rerun_bytes=MB
            )
            if run_id != 2:  # run 2's result never reached the store
                store(target, [result], path)
            files.append(path)
        before = shutil.disk_usage(folder)
        limit_pct = 100.0 * before.used / (before.used + before.free) - 20.0  # 4 MB to free
        scope = RetentionScope(
            folder, ("st1",), RetentionSection(max_disk_used_pct=limit_pct), target, ()
        )
        with ResultsStore(target) as opened:
            plan = plan_pass(scope, opened, FileResultsCache(), time.time_ns())
            outcome = delete_planned(plan)
        gone = [d.file.path for d in outcome.deleted]
        assert gone == [files[0], *files[2 : len(gone) + 1]]  # the oldest, run 2 passed over
        assert {d.reason for d in outcome.deleted} == {DISK}
        assert [(d.file.path, d.reason) for d in plan.kept] == [(files[1], NOT_STORED)]
        assert all(not p.exists() and not p.with_suffix(".rrd").exists() for p in gone)
        after = shutil.disk_usage(folder)
        after_pct = 100.0 * after.used / (after.used + after.free)
        assert after_pct <= limit_pct  # at its limit ...
        one_file_pct = 100.0 * outcome.deleted[-1].file.disk_bytes / (after.used + after.free)
        assert after_pct > limit_pct - one_file_pct  # ... not a file further
        assert plan.disk_short_bytes == 0


def test_the_planner_sees_what_the_measure_says(tmp_path: Path) -> None:
    """The disk measure is a parameter (shutil.disk_usage's shape): a file system said to be
    95 % full makes the oldest file go; one at 50 % nothing."""
    target = StoreTarget(sqlite_path=tmp_path / "recordings" / "results.sqlite")
    folder = tmp_path / "recordings"
    now_ns = time.time_ns()
    paths = [
        write_run_file(folder, run_id, now_ns - (5 - run_id) * DAY_NS, [run_result(run_id)])
        for run_id in (1, 2, 3)
    ]
    for run_id, path in zip((1, 2, 3), paths, strict=True):
        store(target, [run_result(run_id)], path)
    scope = RetentionScope(folder, ("st1",), RetentionSection(max_disk_used_pct=90), target, ())
    needed = paths[0].stat().st_blocks * 512 + paths[0].with_suffix(".rrd").stat().st_blocks * 512

    def full(_: Path) -> Usage:
        return Usage(total=10 * needed, used=10 * needed, free=0)  # 100 %: 1 file over 90 %

    def half(_: Path) -> Usage:
        return Usage(total=10 * needed, used=5 * needed, free=5 * needed)

    with ResultsStore(target) as opened:
        plan = plan_pass(scope, opened, FileResultsCache(), now_ns, measure=full)
        assert [d.file.path for d in plan.deletions] == [paths[0]]
        assert not plan_pass(scope, opened, FileResultsCache(), now_ns, measure=half).deletions
