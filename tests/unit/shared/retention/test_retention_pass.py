"""A retention pass over real run files (MCAP, the .rrd beside) against a real results store,
SQLite and PostgreSQL: what goes, what stays and why, and that what is planned is what is
deleted."""

from __future__ import annotations

import os
import time
from pathlib import Path

from shared.config import RetentionSection
from shared.results import ResultsStore, StoreTarget
from shared.retention import (
    AGE,
    NEWEST,
    NOK_AGE,
    NOT_STORED,
    OPEN,
    RECENT,
    UNREADABLE,
    Decision,
    FileResultsCache,
    RetentionPlan,
    RetentionScope,
    delete_planned,
    list_recordings,
    plan_pass,
)
from shared.retention.pruning import CHANGED
from tests.support.retention_files import DAY_NS, run_result, store, write_run_file

NOW_NS = time.time_ns()
S = 10**9
MONTH = RetentionSection(keep_days=30, keep_nok_days=365)


def _scope(folder: Path, target: StoreTarget, policy: RetentionSection = MONTH) -> RetentionScope:
    return RetentionScope(folder, ("st1", "st2"), policy, target, ())


def _plan(scope: RetentionScope) -> RetentionPlan:
    with ResultsStore(scope.target) as opened:
        return plan_pass(scope, opened, FileResultsCache(), time.time_ns())


def _names(decisions: list[Decision]) -> dict[str, str]:
    return {d.file.path.name: d.reason for d in decisions}


def _recorded(
    folder: Path,
    days_ago: float,
    run_id: int | None,
    verdict: str | None,
    target: StoreTarget | None,
) -> Path:
    """Run ``run_id``'s file of st1, written ``days_ago``, with its result (``verdict`` None:
    none), stored when ``target`` is given."""
    results = [] if verdict is None or run_id is None else [run_result(run_id, verdict)]
    path = write_run_file(folder, run_id, NOW_NS - round(days_ago * DAY_NS), results)
    if target is not None and results:
        store(target, results, path)
    return path


def test_old_ok_files_go_nok_files_stay_longer_unstored_files_stay(
    tmp_path: Path, target: StoreTarget
) -> None:
    folder = tmp_path / "recordings"
    ok = _recorded(folder, 40, 1, "OK", target)
    nok = _recorded(folder, 40.1, 2, "NOK", target)
    unstored = _recorded(folder, 40.2, 3, "OK", None)
    aborted = _recorded(folder, 40.3, 4, None, None)  # a run with no result: its age decides
    idle = _recorded(folder, 45, None, None, None)
    old_nok = _recorded(folder, 400, 5, "NOK", target)
    recent = _recorded(folder, 2, 6, "OK", target)
    newest = _recorded(folder, 1, 7, "OK", None)
    scope = _scope(folder, target)

    plan = _plan(scope)
    assert _names(plan.deletions) == {
        old_nok.name: NOK_AGE,
        idle.name: AGE,
        ok.name: AGE,
        aborted.name: AGE,
    }
    assert [d.file.path for d in plan.deletions] == [old_nok, idle, aborted, ok]  # oldest first
    assert _names(plan.kept) == {unstored.name: NOT_STORED}
    everything = [ok, nok, unstored, aborted, idle, old_nok, recent, newest]
    assert all(path.exists() and path.with_suffix(".rrd").exists() for path in everything)

    outcome = delete_planned(_plan(scope))
    assert [d.file.path for d in outcome.deleted] == [d.file.path for d in plan.deletions]
    assert not outcome.failed
    for path in everything:
        gone = path in (ok, aborted, idle, old_nok)
        assert path.exists() is not gone and path.with_suffix(".rrd").exists() is not gone
    assert not old_nok.parent.exists()  # its day folder, emptied, went with it
    assert not _plan(scope).deletions  # nothing more


def test_a_late_result_in_the_next_runs_file_keeps_that_file_until_it_is_stored(
    tmp_path: Path, target: StoreTarget
) -> None:
    """Run 10's result arrived after run 11 had started: it is in run 11's file, which holds
    run 11's own result too; run 11's is stored, run 10's not yet."""
    folder = tmp_path / "recordings"
    late, own = run_result(10, "OK"), run_result(11, "OK")
    path = write_run_file(folder, 11, NOW_NS - 40 * DAY_NS, [late, own])
    store(target, [own], path)
    _recorded(folder, 1, 12, "OK", target)
    scope = _scope(folder, target, RetentionSection(keep_days=30))
    assert _names(_plan(scope).kept) == {path.name: NOT_STORED}
    store(target, [late], path)
    assert _names(delete_planned(_plan(scope)).deleted) == {path.name: AGE}


def test_every_part_of_a_nok_run_is_kept_as_long_as_its_result(
    tmp_path: Path, target: StoreTarget
) -> None:
    """A run past the size limit: part 1 holds no result, part 2 the NOK one; both are the
    NOK run's curve."""
    folder = tmp_path / "recordings"
    first = _recorded(folder, 40, 20, None, None)
    second = write_run_file(folder, 20, NOW_NS - 40 * DAY_NS + S, [run_result(20, "NOK")], part=2)
    store(target, [run_result(20, "NOK")], second)
    _recorded(folder, 1, 21, "OK", target)
    plan = _plan(_scope(folder, target))
    assert not plan.deletions and not plan.kept
    assert first.exists() and "_part2" in second.name


def test_an_unreadable_file_is_kept_and_an_empty_one_goes(
    tmp_path: Path, target: StoreTarget
) -> None:
    folder = tmp_path / "recordings"
    readable = _recorded(folder, 40, 30, "OK", target)
    day = readable.parent
    garbage, empty = day / "st1_run31_010203.mcap", day / "st1_run32_010204.mcap"
    garbage.write_bytes(b"not an MCAP file at all")
    empty.write_bytes(b"")  # a recorder that died as it opened the file
    for path in (garbage, empty):
        os.utime(path, ns=(NOW_NS - 40 * DAY_NS, NOW_NS - 40 * DAY_NS))
    _recorded(folder, 1, 33, "OK", target)
    plan = _plan(_scope(folder, target))
    assert _names(plan.kept) == {garbage.name: UNREADABLE}
    assert _names(plan.deletions) == {readable.name: AGE, empty.name: AGE}


def test_the_newest_file_of_a_station_and_files_written_lately_are_never_touched(
    tmp_path: Path, target: StoreTarget
) -> None:
    """st2's only file is a year old (a station stopped since: its recorder's file may be
    open); a run file named a year ago but written ten minutes ago (a spool's resend) too."""
    folder = tmp_path / "recordings"
    lone = write_run_file(
        folder, 1, NOW_NS - 365 * DAY_NS, [run_result(1, station="st2")], station="st2"
    )
    store(target, [run_result(1, station="st2")], lone)
    resent = _recorded(folder, 365, 40, "OK", target)
    os.utime(resent, ns=(NOW_NS - 600 * S, NOW_NS - 600 * S))
    _recorded(folder, 200, 41, "OK", target)
    newest = _recorded(folder, 100, 42, "OK", target)
    files = {f.path.name: f.protected for f in list_recordings(folder, ("st1", "st2"), NOW_NS)}
    assert files[lone.name] == files[newest.name] == NEWEST and files[resent.name] == RECENT
    plan = _plan(_scope(folder, target, RetentionSection(keep_days=1, max_disk_used_pct=1)))
    assert [d.file.run_id for d in plan.deletions] == [41]


def test_a_file_written_again_after_it_was_judged_is_not_deleted(
    tmp_path: Path, target: StoreTarget
) -> None:
    folder = tmp_path / "recordings"
    old = _recorded(folder, 40, 50, "OK", target)
    _recorded(folder, 1, 51, "OK", target)
    plan = _plan(_scope(folder, target))
    assert _names(plan.deletions) == {old.name: AGE}
    os.utime(old, ns=(NOW_NS, NOW_NS))
    outcome = delete_planned(plan)
    assert not outcome.deleted and [why for _, why in outcome.failed] == [CHANGED]
    assert old.exists()


def test_a_file_the_recorder_says_is_open_is_protected(tmp_path: Path) -> None:
    folder = tmp_path / "recordings"
    old = write_run_file(folder, 60, NOW_NS - 40 * DAY_NS)
    write_run_file(folder, 61, NOW_NS - 30 * DAY_NS)
    listed = list_recordings(folder, ("st1",), NOW_NS, open_paths=[old])
    assert [(f.run_id, f.protected) for f in listed] == [(60, OPEN), (61, NEWEST)]
    assert list_recordings(folder, ("st1",), NOW_NS)[0].protected is None
