"""A retention plan carried out: each file deleted with the ``.rrd`` beside it, and the day
folders left empty.

A file changed since it was planned (written again: not the file the plan
judged) is left alone. The ``.rrd`` goes first: cut off between the two,
the ``.mcap`` is still there and goes at the next pass, while an ``.rrd``
left alone would never be listed again. A file that cannot be deleted
(permissions, a read-only disk) is said why, and the rest go on.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass, field
from pathlib import Path

from shared.files import describe_os_error
from shared.retention.retention_plan import Decision, RetentionPlan

CHANGED = "written since it was judged"


@dataclass
class PruneOutcome:
    deleted: list[Decision] = field(default_factory=list)
    failed: list[tuple[Decision, str]] = field(default_factory=list)  # and why

    @property
    def deleted_bytes(self) -> int:
        return sum(decision.file.size_bytes for decision in self.deleted)


def delete_planned(plan: RetentionPlan) -> PruneOutcome:
    """Delete every file of ``plan`` (with its ``.rrd``); the day folders left empty too."""
    outcome = PruneOutcome()
    days: set[Path] = set()
    for decision in plan.deletions:
        recording = decision.file
        try:
            stat = recording.path.stat()
            rerun_mtime_ns = _modified_ns(recording.rerun)
            if max(stat.st_mtime_ns, rerun_mtime_ns) != recording.modified_ns:
                outcome.failed.append((decision, CHANGED))
                continue
            recording.rerun.unlink(missing_ok=True)
            recording.path.unlink()
        except FileNotFoundError:
            continue  # gone already (a person, another pass): nothing to do
        except OSError as err:
            outcome.failed.append((decision, describe_os_error(err, recording.path)))
            continue
        outcome.deleted.append(decision)
        days.add(recording.path.parent)
    for day in days:
        with contextlib.suppress(OSError):  # not empty (other files), or gone
            day.rmdir()
    return outcome


def _modified_ns(path: Path) -> int:
    """When ``path`` was last written; 0: there is none."""
    try:
        return path.stat().st_mtime_ns
    except FileNotFoundError:
        return 0
