"""How an import puts a run's files in place: whole, or not at all.

A run is written under hidden temporary names in its own day folder
(``.<stem>.<pid>.importing.mcap`` and ``.rrd``) and renamed to its real name
(``<stem>.mcap``, ``.rrd``) only when both are complete: the ``.rrd`` first,
then the ``.mcap``, so a ``.mcap`` under its real name always means a
finished import. On any failure the temporary files are removed; those of an
import that was killed (its process is gone) are removed by the next import
of the same run.

What an earlier import left of a run is told apart by reading it back
(:class:`RecordedCopy`): a complete file holding every sample of the run and
its predictor summary is "already there"; any other file carrying a
``controller`` record (an import's, e.g. cut short or written before imports
replayed the predictor) is replaced; a file without one (a live recording of
the same station and run id) is never touched.
"""

from __future__ import annotations

import contextlib
import os
import re
from dataclasses import dataclass
from pathlib import Path

from mcap.records import Message, Metadata

from shared.contract import RunSummary, channels, decode
from shared.errors import InputError
from shared.files import fsync_path
from shared.recordings.mcap import RecordingScan

TEMPORARY_MARK = ".importing"
CONTROLLER_RECORD = "controller"
_SAMPLE_SCHEMA = channels.SAMPLES.schema_name
_SUMMARY_SCHEMA = channels.RUNS.schema_name
_TEMPORARY = re.compile(r"^\.(?P<stem>.+)\.(?P<pid>\d+)" + re.escape(TEMPORARY_MARK) + r"\.\w+$")


@dataclass(frozen=True, slots=True)
class RecordedCopy:
    """A run file found in the recordings folder, read back."""

    path: Path
    complete: bool  # the footer was reached
    imported: bool  # carries a ``controller`` record: written by an import
    samples: int
    summary: RunSummary | None  # the last RunSummary in it

    def holds(self, samples: int) -> bool:
        """True when this is a finished import of a run of ``samples`` samples."""
        return (
            self.imported and self.complete and self.samples == samples and self.summary is not None
        )


def read_copy(path: Path) -> RecordedCopy:
    """What ``path`` holds; an unreadable file is an incomplete, foreign copy."""
    scan = RecordingScan(path)
    imported = False
    samples = 0
    summary: RunSummary | None = None
    try:
        for record in scan.records():
            if isinstance(record, Metadata):
                imported = imported or record.name == CONTROLLER_RECORD
            elif isinstance(record, Message):
                channel = scan.channels.get(record.channel_id)
                schema = scan.schemas.get(channel.schema_id) if channel is not None else None
                name = schema.name if schema is not None else None
                if name == _SAMPLE_SCHEMA:
                    samples += 1
                elif name == _SUMMARY_SCHEMA:
                    summary = decode(RunSummary, record.data)
    except InputError:
        return RecordedCopy(path, False, imported, samples, summary)
    return RecordedCopy(path, scan.complete, imported, samples, summary)


def temporary_path(final: Path) -> Path:
    """The hidden name ``final`` is written under until it is complete (same folder)."""
    return final.with_name(f".{final.stem}.{os.getpid()}{TEMPORARY_MARK}{final.suffix}")


def remove_temporary(paths: list[Path]) -> None:
    """Remove temporary files; never raises (it runs on the failure path)."""
    for path in paths:
        with contextlib.suppress(OSError):
            path.unlink(missing_ok=True)


def remove_leftovers(day: Path, stem_prefix: str) -> list[Path]:
    """Temporary files of ``stem_prefix`` left by imports that were killed; removed."""
    removed: list[Path] = []
    for path in day.glob(f".{stem_prefix}*{TEMPORARY_MARK}.*"):
        match = _TEMPORARY.match(path.name)
        if match is None or _alive(int(match["pid"])):
            continue
        with contextlib.suppress(FileNotFoundError):
            path.unlink()
            removed.append(path)
    return removed


def put_in_place(moves: list[tuple[Path, Path]]) -> None:
    """Rename each (temporary, final) in order, then sync the folder so the names last."""
    for temporary, final in moves:
        os.replace(temporary, final)
    folders = {final.parent for _, final in moves}
    for folder in folders:
        fsync_path(folder)


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's process
        return True
    return True
