"""A retention plan in words: per reason, how many files, how many bytes, written from when
to when (UTC): the recorder's log line and ``boltwatch recordings prune``'s summary."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from datetime import UTC, datetime

from shared.config import RetentionSection
from shared.retention.disk_usage import DiskUsage
from shared.retention.retention_plan import (
    AGE,
    DELETED_REASONS,
    DISK,
    KEPT_REASONS,
    NOK_AGE,
    NOT_STORED,
    Decision,
)


@dataclass
class Tally:
    """Files of one kind: how many, their bytes, the oldest and newest written."""

    files: int = 0
    size_bytes: int = 0
    oldest_ns: int | None = None
    newest_ns: int | None = None

    def add(self, decision: Decision) -> None:
        recording = decision.file
        self.files += 1
        self.size_bytes += recording.size_bytes
        modified = recording.modified_ns
        self.oldest_ns = modified if self.oldest_ns is None else min(self.oldest_ns, modified)
        self.newest_ns = modified if self.newest_ns is None else max(self.newest_ns, modified)

    def text(self) -> str:
        """``12 files, 1.2 MB, written 2026-01-02 08:00 to 2026-01-31 17:55 UTC``."""
        if self.oldest_ns is None or self.newest_ns is None:
            return "no files"
        files = f"{self.files} file{'' if self.files == 1 else 's'}"
        written = utc_minute(self.oldest_ns)
        if self.newest_ns != self.oldest_ns:
            written += f" to {utc_minute(self.newest_ns)}"
        return f"{files}, {bytes_text(self.size_bytes)}, written {written} UTC"


def tallies(decisions: Iterable[Decision], reasons: Iterable[str]) -> dict[str, Tally]:
    """A tally per reason of ``reasons`` that has files, in that order; ``""``: all of them."""
    by_reason: dict[str, Tally] = {reason: Tally() for reason in reasons}
    total = Tally()
    for decision in decisions:
        by_reason[decision.reason].add(decision)
        total.add(decision)
    found = {reason: tally for reason, tally in by_reason.items() if tally.files}
    return {"": total, **found} if total.files else {}


def deleted_tallies(decisions: Iterable[Decision]) -> dict[str, Tally]:
    return tallies(decisions, DELETED_REASONS)


def kept_tallies(decisions: Iterable[Decision]) -> dict[str, Tally]:
    return tallies(decisions, KEPT_REASONS)


def reason_text(reason: str, policy: RetentionSection, usage: DiskUsage | None = None) -> str:
    """Why, with the policy's figures: ``older than keep_days (30 days)``."""
    if reason == AGE:
        return f"older than keep_days ({policy.keep_days} days)"
    if reason == NOK_AGE:
        return f"NOK, older than keep_nok_days ({policy.keep_nok_days} days)"
    if reason == DISK:
        used = "" if usage is None else f"; {usage.used_pct:.1f} % used"
        limit = f"{policy.max_disk_used_pct:g} %{used}"
        return f"the oldest while the disk is above max_disk_used_pct ({limit})"
    if reason == NOT_STORED:
        return "results not in the store ('boltwatch results rebuild' stores them)"
    return reason


def bytes_text(size_bytes: int) -> str:
    """``532 B``, ``12.3 kB``, ``4.56 MB``, ``1.20 GB`` (decimal, as df -H)."""
    if size_bytes < 1000:
        return f"{size_bytes} B"
    value = float(size_bytes)
    for unit in ("kB", "MB", "GB", "TB"):
        value /= 1000
        if value < 1000 or unit == "TB":
            return f"{value:.3g} {unit}"
    raise AssertionError("unreachable")


def utc_minute(time_ns: int) -> str:
    return f"{datetime.fromtimestamp(time_ns / 1e9, UTC):%Y-%m-%d %H:%M}"
