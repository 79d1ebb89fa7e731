"""What a run file holds, and whether the results store has it: the question asked of every
file before a retention rule deletes it.

The file itself says which results it holds (its ``results`` messages: the
run's own, and a late result of the run before it that arrived after the
next run had started); the store says which of them it has. Asking the
store alone ("the rows whose recording is this file") could not tell a file
holding no result (an aborted run, an idle file) from one whose result never
reached the store: neither has a row. So the file is read, once: closed
files do not change, and :class:`FileResultsCache` keeps what each held by
(path, size, modification time).

A file is NOK when a result in it is NOK, or when the stored result of the
run its name names is (a run past the size or duration limit is in several
files, its result in the last; each of them is that run's curve). A file
that cannot be read (permissions, not MCAP) is kept and said so; a file cut
short (a recorder killed) is judged by the results readable in it, which is
all anything can ever read of it.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from shared.contract import TighteningResult, channels, decode
from shared.errors import InputError
from shared.recordings.mcap import RecordingScan
from shared.results import ResultsStore
from shared.retention.recording_files import RecordingFile

_RESULTS = "/" + channels.RESULTS.topic

#: a result in a file: (station, run_id, OK/NOK)
HeldResult = tuple[str, int, str]


@dataclass(frozen=True, slots=True)
class FileHoldings:
    """What a run file holds, against the store."""

    results: int = 0  # results in the file
    not_stored: int = 0  # of them, not in the results store
    nok: bool = False  # a NOK result in it, or its run's stored result is NOK
    unreadable: str | None = None  # why the file cannot be read; then it is kept


class FileResultsCache:
    """What each file held when it was read, by (path, size, modification time); and, once
    the store has every result of it and its run's, what it holds against the store (a
    stored result stays stored, its verdict the first one stored: that answer is final)."""

    def __init__(self) -> None:
        self._known: dict[Path, _Known] = {}

    def holdings(self, recording: RecordingFile, store: ResultsStore) -> FileHoldings:
        """What ``recording`` holds and whether ``store`` has it (a StoreError when the store
        cannot be asked)."""
        try:
            known = self._read(recording)
        except InputError as err:
            return FileHoldings(unreadable=str(err))
        if known.final is not None:
            return known.final
        keys = [(station, run_id) for station, run_id, _ in known.held]
        own_run = None if recording.run_id is None else (recording.station, recording.run_id)
        stored = store.verdicts(keys + ([own_run] if own_run is not None else []))
        holdings = FileHoldings(
            results=len(keys),
            not_stored=sum(1 for key in keys if key not in stored),
            nok=any(verdict == "NOK" for *_, verdict in known.held)
            or (own_run is not None and stored.get(own_run) == "NOK"),
        )
        if not holdings.not_stored and (own_run is None or own_run in stored):
            known.final = holdings
        return holdings

    def keep_only(self, recordings: list[RecordingFile]) -> None:
        """Forget every file but ``recordings`` (the rest are gone)."""
        listed = {recording.path for recording in recordings}
        for path in [path for path in self._known if path not in listed]:
            del self._known[path]

    def _read(self, recording: RecordingFile) -> _Known:
        path = recording.path
        try:
            stat = os.stat(path)
        except OSError as err:
            raise InputError(f"{path}: cannot be read: {err.strerror}") from err
        version = (stat.st_size, stat.st_mtime_ns)
        known = self._known.get(path)
        if known is not None and known.version == version:
            return known
        held: tuple[HeldResult, ...] = ()
        if stat.st_size > 0:  # an empty file (a recorder that died at once) holds nothing
            held = tuple(
                (result.station, result.run_id, result.result)
                # a refused payload is kept raw, never in the store
                for _, _, message in RecordingScan(path).typed_messages(_RESULTS)
                for result in [decode(TighteningResult, message.data)]
            )
        known = self._known[path] = _Known(version, held)
        return known


@dataclass(slots=True)
class _Known:
    version: tuple[int, int]  # (size, modification time) when it was read
    held: tuple[HeldResult, ...]
    final: FileHoldings | None = None  # what it holds against the store, once that is final
