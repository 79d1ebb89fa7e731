"""What a recorder that crashed left: run files still under their writing name, finished.

A recorder writes each run file as ``.<name>.writing`` and renames it ``<name>``
once complete (:class:`~shared.recordings.mcap.mcap_sink.McapSink`,
``rename_when_complete``). A file still under its writing name when the
recorder starts was left by one that was killed, lost its power or its disk:
:func:`finish_unfinished` copies every complete record of it (as ``boltwatch
recover`` does) into ``.<name>.recovering``, syncs it, renames it ``<name>``,
removes the writing file and syncs the folder. So a crash never leaves a broken
file under a run file's name, and no run file is lost: a file holding no
message at all (the recorder died before its first flush) is removed, one that
cannot be read (not MCAP, or the disk fails again) is left as it is and named
in the log.

It runs only in the recorder that holds the recordings folder
(:mod:`services.recorder.station_holder`): a file being written by a live
recorder must never be taken for a crash's.
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass
from pathlib import Path

from shared.errors import InputError
from shared.files import describe_os_error, fsync_path
from shared.recordings.layout import final_path_of, unfinished_files
from shared.recordings.mcap.recording_reader import RecordingScan
from shared.recordings.mcap.recovery import default_target, recover

LOG = logging.getLogger(__name__)

RECOVERING_SUFFIX = ".recovering"


@dataclass(frozen=True, slots=True)
class Unfinished:
    """One file found under its writing name, and what became of it."""

    writing: Path
    final: Path | None  # its run file now; None: removed (no message) or left (unreadable)
    messages: int  # messages in the run file
    was_complete: bool  # finished, only its rename was missing
    problem: str | None  # why it was left as it is


@dataclass(frozen=True, slots=True)
class FinishedCount:
    """What :func:`finish_unfinished` did, counted (for the log and ``RecorderStats``)."""

    files: list[Unfinished]

    @property
    def finished(self) -> int:
        return sum(1 for one in self.files if one.final is not None)

    @property
    def messages(self) -> int:
        return sum(one.messages for one in self.files)

    @property
    def left(self) -> list[Unfinished]:
        return [one for one in self.files if one.problem is not None]


def finish_unfinished(folder: Path) -> FinishedCount:
    """Finish every file of ``folder`` still under its writing name; what was done, logged."""
    done = FinishedCount([finish_one(writing) for writing in unfinished_files(folder)])
    if done.files:
        LOG.warning(
            "%d run files were left unfinished by a recorder that stopped without closing "
            "them: %d finished under their names with %d messages, %d removed (no message), "
            "%d left as they are",
            len(done.files),
            done.finished,
            done.messages,
            len(done.files) - done.finished - len(done.left),
            len(done.left),
        )
    return done


def finish_one(writing: Path) -> Unfinished:
    """Give ``writing`` (a file under its writing name) its run file's name, recovered."""
    final = final_path_of(writing)
    if final is None:
        raise ValueError(f"{writing} is not a file under its writing name")
    if final.exists():  # never replaces a run file (a copy made by hand, say)
        final = default_target(final)
    staging = writing.with_name(writing.name + RECOVERING_SUFFIX)
    try:
        scan = RecordingScan(writing)
        if _is_complete(scan):
            messages = sum(1 for _ in RecordingScan(writing).messages())
            _put_in_place(writing, final)
            LOG.info("%s was complete: renamed %s (%d messages)", writing, final.name, messages)
            return Unfinished(writing, final, messages, True, None)
        report = recover(writing, staging)
        if report.messages == 0:
            staging.unlink()
            writing.unlink()
            LOG.info("%s held no message: removed", writing)
            return Unfinished(writing, None, 0, False, None)
        fsync_path(staging)
        _put_in_place(staging, final)
        writing.unlink()
    except (InputError, OSError) as err:
        staging.unlink(missing_ok=True)
        problem = describe_os_error(err, writing) if isinstance(err, OSError) else str(err)
        if isinstance(err, InputError) and _is_empty(writing):
            writing.unlink(missing_ok=True)  # not even a header reached the disk
            LOG.info("%s was empty: removed", writing)
            return Unfinished(writing, None, 0, False, None)
        LOG.error("%s could not be finished, left as it is: %s", writing, problem)
        return Unfinished(writing, None, 0, False, problem)
    LOG.info("%s finished as %s", writing.name, final.name)  # recover() logged the counts
    return Unfinished(writing, final, report.messages, False, None)


def _is_complete(scan: RecordingScan) -> bool:
    """Every record read and the footer reached (a crash between finish and rename)."""
    for _ in scan.records():
        pass
    return scan.complete


def _is_empty(path: Path) -> bool:
    try:
        return path.stat().st_size == 0
    except OSError:
        return False


def _put_in_place(source: Path, final: Path) -> None:
    os.rename(source, final)
    fsync_path(final.parent)
