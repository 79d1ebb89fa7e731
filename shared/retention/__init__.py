"""How long the curves are kept: a station file's ``[retention]`` applied to its recordings.

The results store keeps every result for ever; the recordings (the curves)
go when the policy says, and never before every result in them is stored.

- :mod:`.recording_files` (the run files of a folder's stations: size, last
  written, protected: open, the newest of its station, written in the last hour)
- :mod:`.disk_usage` (how full the file system is, as ``df`` counts it)
- :mod:`.file_holdings` (what a file holds against the store: its results,
  stored or not, NOK or not; read once per file)
- :mod:`.retention_plan` (which files go and why: the one decision, pure)
- :mod:`.pruning` (a plan carried out: each file with its ``.rrd``, empty day folders)
- :mod:`.retention_pass` (a folder's scope from station files; one pass planned)
- :mod:`.retention_summary` (a plan in words: files, bytes, oldest and newest per reason)

The recorder runs a pass every few minutes on a thread of its own
(``services/recorder/retention_watch.py``); ``boltwatch recordings prune``
runs one (``--dry-run``: says it).
"""

from shared.retention.disk_usage import DiskUsage, Measure, disk_usage_of
from shared.retention.file_holdings import FileHoldings, FileResultsCache
from shared.retention.pruning import PruneOutcome, delete_planned
from shared.retention.recording_files import (
    NEWEST,
    OPEN,
    RECENT,
    RECENT_NS,
    RecordingFile,
    list_recordings,
)
from shared.retention.retention_pass import RetentionScope, plan_pass, retention_scopes
from shared.retention.retention_plan import (
    AGE,
    DELETED_REASONS,
    DISK,
    KEPT_REASONS,
    NOK_AGE,
    NOT_STORED,
    UNREADABLE,
    Decision,
    RetentionPlan,
    plan_retention,
)
from shared.retention.retention_summary import (
    Tally,
    bytes_text,
    deleted_tallies,
    kept_tallies,
    reason_text,
    utc_minute,
)

__all__ = [
    "AGE",
    "DELETED_REASONS",
    "DISK",
    "KEPT_REASONS",
    "NEWEST",
    "NOK_AGE",
    "NOT_STORED",
    "OPEN",
    "RECENT",
    "RECENT_NS",
    "UNREADABLE",
    "Decision",
    "DiskUsage",
    "FileHoldings",
    "FileResultsCache",
    "Measure",
    "PruneOutcome",
    "RecordingFile",
    "RetentionPlan",
    "RetentionScope",
    "Tally",
    "bytes_text",
    "delete_planned",
    "deleted_tallies",
    "disk_usage_of",
    "kept_tallies",
    "list_recordings",
    "plan_pass",
    "plan_retention",
    "reason_text",
    "retention_scopes",
    "utc_minute",
]
