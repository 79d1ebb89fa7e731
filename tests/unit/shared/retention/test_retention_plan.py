"""The planner alone: files, what each holds against the store, the time and the disk in;
which files go and why out. No file is read and no store asked here: the holdings are a
table, the disk a figure, as the planner's contract says."""

from __future__ import annotations

from pathlib import Path

import pytest

from shared.config import RetentionSection
from shared.retention import (
    AGE,
    DISK,
    NEWEST,
    NOK_AGE,
    NOT_STORED,
    OPEN,
    UNREADABLE,
    DiskUsage,
    FileHoldings,
    RecordingFile,
    RetentionPlan,
    plan_retention,
)

DAY_NS = 86_400 * 10**9
NOW_NS = 1_800_000_000 * 10**9
MB = 1_000_000


def _file(
    run_id: int, age_days: float, disk_mb: int = 1, protected: str | None = None
) -> RecordingFile:
    return RecordingFile(
        path=Path(f"/recordings/st1/day/st1_run{run_id}_000000.mcap"),
        station="st1",
        run_id=run_id,
        size_bytes=disk_mb * MB,
        disk_bytes=disk_mb * MB,
        modified_ns=NOW_NS - round(age_days * DAY_NS),
        protected=protected,
    )


class Holdings:
    """What each run's file holds (by run id), and which files were asked about."""

    def __init__(self, table: dict[int, FileHoldings]) -> None:
        self.table = table
        self.asked: list[int] = []

    def __call__(self, recording: RecordingFile) -> FileHoldings:
        assert recording.run_id is not None
        self.asked.append(recording.run_id)
        return self.table.get(recording.run_id, FileHoldings(results=1))


def _gone(plan: RetentionPlan) -> dict[int | None, str]:
    return {d.file.run_id: d.reason for d in plan.deletions}


def _kept(plan: RetentionPlan) -> dict[int | None, str]:
    return {d.file.run_id: d.reason for d in plan.kept}


def test_old_ok_files_go_nok_files_stay_longer() -> None:
    policy = RetentionSection(keep_days=30, keep_nok_days=365)
    files = [_file(1, 31), _file(2, 29), _file(3, 100), _file(4, 366)]
    holdings = Holdings(
        {3: FileHoldings(results=1, nok=True), 4: FileHoldings(results=1, nok=True)}
    )
    plan = plan_retention(files, policy, NOW_NS, holdings)
    assert _gone(plan) == {4: NOK_AGE, 1: AGE}
    assert [d.file.run_id for d in plan.deletions] == [4, 1]  # oldest first
    assert not plan.kept
    assert 2 not in holdings.asked  # within its time: nothing to ask


def test_without_keep_nok_days_a_nok_file_goes_with_the_rest() -> None:
    plan = plan_retention(
        [_file(1, 31)],
        RetentionSection(keep_days=30),
        NOW_NS,
        Holdings({1: FileHoldings(1, 0, True)}),
    )
    assert _gone(plan) == {1: NOK_AGE}


def test_a_file_whose_results_are_not_stored_is_kept_and_said_so() -> None:
    holdings = Holdings(
        {
            1: FileHoldings(results=2, not_stored=1),
            2: FileHoldings(unreadable="st1_run2.mcap: cannot be read: Permission denied"),
            3: FileHoldings(results=0),  # an aborted run: judged by its age alone
        }
    )
    plan = plan_retention(
        [_file(1, 40), _file(2, 40), _file(3, 40)], RetentionSection(keep_days=30), NOW_NS, holdings
    )
    assert _gone(plan) == {3: AGE}
    assert _kept(plan) == {1: NOT_STORED, 2: UNREADABLE}


def test_protected_files_are_never_asked_about_nor_deleted() -> None:
    files = [_file(1, 400, protected=OPEN), _file(2, 400, protected=NEWEST)]
    holdings = Holdings({})
    plan = plan_retention(
        files,
        RetentionSection(keep_days=1, max_disk_used_pct=10),
        NOW_NS,
        holdings,
        DiskUsage(used_bytes=99 * MB, free_bytes=1 * MB),
    )
    assert not plan.deletions and not plan.kept and holdings.asked == []
    assert plan.disk_short_bytes == 89 * MB


def test_the_disk_rule_deletes_the_oldest_first_until_at_its_limit() -> None:
    """95 MB of 100 used, at most 90 %: 5 MB to free; the oldest stored files go, NOK or not,
    a file whose result is not stored is passed over."""
    files = [_file(run, age_days=10 - run, disk_mb=2) for run in range(1, 9)]
    holdings = Holdings({2: FileHoldings(results=1, not_stored=1), 3: FileHoldings(1, 0, True)})
    usage = DiskUsage(used_bytes=95 * MB, free_bytes=5 * MB)
    plan = plan_retention(files, RetentionSection(max_disk_used_pct=90), NOW_NS, holdings, usage)
    assert _gone(plan) == {1: DISK, 3: DISK, 4: DISK}
    assert _kept(plan) == {2: NOT_STORED}
    assert plan.freed_bytes == 6 * MB and plan.disk_short_bytes == 0
    assert holdings.asked == [1, 2, 3, 4]  # none past what it needed


def test_what_the_age_rule_frees_counts_toward_the_disk() -> None:
    files = [_file(1, 40, disk_mb=3), _file(2, 20, disk_mb=3), _file(3, 10, disk_mb=3)]
    usage = DiskUsage(used_bytes=95 * MB, free_bytes=5 * MB)
    policy = RetentionSection(keep_days=30, max_disk_used_pct=90)
    plan = plan_retention(files, policy, NOW_NS, Holdings({}), usage)
    assert _gone(plan) == {1: AGE, 2: DISK}


def test_below_its_limit_the_disk_rule_deletes_nothing() -> None:
    holdings = Holdings({})
    usage = DiskUsage(used_bytes=50 * MB, free_bytes=50 * MB)
    plan = plan_retention(
        [_file(1, 400)], RetentionSection(max_disk_used_pct=90), NOW_NS, holdings, usage
    )
    assert not plan.deletions and holdings.asked == []


def test_when_nothing_more_may_go_the_plan_says_how_much_is_short() -> None:
    holdings = Holdings({1: FileHoldings(results=1, not_stored=1)})
    usage = DiskUsage(used_bytes=95 * MB, free_bytes=5 * MB)
    plan = plan_retention(
        [_file(1, 5, disk_mb=2), _file(2, 4, disk_mb=1)],
        RetentionSection(max_disk_used_pct=90),
        NOW_NS,
        holdings,
        usage,
    )
    assert _gone(plan) == {2: DISK} and _kept(plan) == {1: NOT_STORED}
    assert plan.disk_short_bytes == 4 * MB


@pytest.mark.parametrize(
    ("used_mb", "free_mb", "pct", "over_mb"),
    [(95, 5, 90.0, 5), (90, 10, 90.0, 0), (50, 50, 90.0, 0), (80, 20, 50.0, 30)],
)
def test_bytes_over_a_limit(used_mb: int, free_mb: int, pct: float, over_mb: int) -> None:
    usage = DiskUsage(used_bytes=used_mb * MB, free_bytes=free_mb * MB)
    assert usage.bytes_over(pct) == over_mb * MB
    assert usage.used_pct == pytest.approx(100 * used_mb / (used_mb + free_mb))
