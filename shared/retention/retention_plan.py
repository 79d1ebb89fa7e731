"""Which recordings a retention policy deletes now, and why: the one decision, pure.

:func:`plan_retention` takes the run files (:mod:`.recording_files`), the
policy (``[retention]``), the time now, how full the disk is, and what each
file holds against the results store (``holdings``, asked only of the files
a rule would delete, at most once each); it reads no file and asks no store
itself. The recorder's pass and ``boltwatch recordings prune`` both call it,
so ``--dry-run`` lists what either deletes.

The rules, in order:

1. **Age**: a file last written more than ``keep_days`` ago goes; one holding
   a NOK result stays until ``keep_nok_days``.
2. **Disk**: while the file system is fuller than ``max_disk_used_pct``, the
   oldest remaining files go first (NOK or not: a full disk stops the
   recording) until what they free brings it down to the limit; what the
   age rule deletes counts first.

Whatever the rule, a file is kept when it is protected (open, the newest of
its station, written in the last hour), when a result in it is not in the
store (:data:`NOT_STORED`: ``boltwatch results rebuild`` stores it), or
when it cannot be read (:data:`UNREADABLE`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from shared.config import RetentionSection
from shared.retention.disk_usage import DiskUsage
from shared.retention.file_holdings import FileHoldings
from shared.retention.recording_files import RecordingFile

AGE = "older than keep_days"
NOK_AGE = "NOK, older than keep_nok_days"
DISK = "oldest while the disk is above max_disk_used_pct"
NOT_STORED = "results not stored"
UNREADABLE = "unreadable"

#: why each kind of file goes, in the order they are told
DELETED_REASONS = (AGE, NOK_AGE, DISK)
KEPT_REASONS = (NOT_STORED, UNREADABLE)


@dataclass(frozen=True, slots=True)
class Decision:
    """A file and why it goes (a reason of DELETED_REASONS) or stays (KEPT_REASONS)."""

    file: RecordingFile
    reason: str


@dataclass
class RetentionPlan:
    deletions: list[Decision] = field(default_factory=list)  # oldest first
    kept: list[Decision] = field(default_factory=list)  # a rule would delete them, but
    usage: DiskUsage | None = None  # the disk before (None: no disk rule)
    disk_short_bytes: int = 0  # what the disk rule could not free (0: at its limit)
    skipped: list[str] = field(default_factory=list)  # a line per entry not looked at

    @property
    def freed_bytes(self) -> int:
        return sum(decision.file.disk_bytes for decision in self.deletions)


def plan_retention(
    files: Sequence[RecordingFile],
    policy: RetentionSection,
    now_ns: int,
    holdings: Callable[[RecordingFile], FileHoldings],
    usage: DiskUsage | None = None,
) -> RetentionPlan:
    """What goes and what is kept past its time (see the module's docstring); ``usage``:
    the disk now, needed by ``max_disk_used_pct`` (None: the disk rule is not applied)."""
    plan = RetentionPlan(usage=usage if policy.max_disk_used_pct is not None else None)
    asked: dict[RecordingFile, FileHoldings] = {}
    decided: set[RecordingFile] = set()

    def held(recording: RecordingFile) -> FileHoldings | None:
        """What it holds; None (and kept, said why) when it may not go whatever it holds."""
        if recording not in asked:
            asked[recording] = holdings(recording)
        found = asked[recording]
        why = UNREADABLE if found.unreadable else NOT_STORED if found.not_stored else None
        if why is None:
            return found
        if recording not in decided:
            decided.add(recording)
            plan.kept.append(Decision(recording, why))
        return None

    oldest_first = sorted(
        (f for f in files if f.protected is None), key=lambda f: (f.modified_ns, str(f.path))
    )
    keep_ns, keep_nok_ns = policy.keep_ns, policy.keep_nok_ns
    if keep_ns is not None and keep_nok_ns is not None:
        for recording in oldest_first:
            age_ns = now_ns - recording.modified_ns
            if age_ns <= keep_ns or (found := held(recording)) is None:
                continue
            if found.nok and age_ns <= keep_nok_ns:
                continue
            decided.add(recording)
            plan.deletions.append(Decision(recording, NOK_AGE if found.nok else AGE))
    if plan.usage is not None and policy.max_disk_used_pct is not None:
        to_free = plan.usage.bytes_over(policy.max_disk_used_pct) - plan.freed_bytes
        for recording in oldest_first:
            if to_free <= 0:
                break
            if recording in decided or held(recording) is None:
                continue
            decided.add(recording)
            plan.deletions.append(Decision(recording, DISK))
            to_free -= recording.disk_bytes
        plan.disk_short_bytes = max(0, to_free)
    plan.deletions.sort(key=lambda d: (d.file.modified_ns, str(d.file.path)))
    return plan
