"""Where a run's recording is, for the line's page: the results store names it, and the page
reads it only where the station's recordings folder holds it.

A run is asked for by station and run id. The page serves the stations of its station
files, each with its recordings folder and results store
(:func:`~shared.results.station_store`). :meth:`RunLocator.locate`:

1. the station must be one of them (else: not this page's station);
2. the store's row of the run names its recording (``recording``, the MCAP file the
   recorder filed the result into); a store that does not answer is said, and the run is
   looked for by the folder's layout alone;
3. the run's files are those the layout gives in the station's folder
   (:func:`~shared.recordings.run_files`: every part of the run, oldest first), and the
   newest under its writing name while the recorder still writes it
   (:func:`~shared.recordings.writing_path`); the file the store names must be one of
   them, and every one must be a regular file whose real path (its symbolic links
   followed) is inside the recordings folder. A store row naming anything else (another
   folder, ``/etc/passwd``, a link out of the folder, a file of another name) is refused
   in words, never read;
   A multi-spindle station's cycle is one file, named by the first of its spindles' runs
   to start: a spindle's run of no file of its own, whose row says its cycle (its sync id),
   has the files of the run the named file is named by, checked the same way;
4. a run the store does not hold yet (the recorder stores a result once its file is
   flushed) is found by the layout alone; with no file either it is not found
   (``pending``: its result may be on its way).

The store is opened, asked and closed in the caller's thread (a worker's). Nothing here
writes.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from shared.config import AnyStation
from shared.errors import InputError, StoreError
from shared.files import real_path
from shared.recordings import (
    file_name_of,
    run_file_prefix,
    run_files,
    station_days,
    writing_path,
)
from shared.results import ResultsQuery, ResultsStore, StoredResult, StoreTarget, station_store

#: the application name a PostgreSQL store sees (its pg_stat_activity)
APPLICATION = "boltwatch serve dashboard"


class RunRequestError(Exception):
    """The run cannot be given: ``status`` (HTTP) and one line why (``pending``: its result
    may be on its way to the store: ask again in a moment)."""

    def __init__(self, status: int, text: str, pending: bool = False) -> None:
        super().__init__(text)
        self.status = status
        self.text = text
        self.pending = pending


@dataclass(frozen=True, slots=True)
class StationRecordings:
    """A station the page serves: its recordings folder (real path) and results store."""

    station: str
    folder: Path
    store: StoreTarget

    @staticmethod
    def of(station: AnyStation) -> StationRecordings:
        return StationRecordings(
            station.station_id, real_path(station.recordings_folder), station_store(station)
        )


@dataclass(frozen=True, slots=True)
class LocatedRun:
    """A run's files on this server, and the store's row of it (None: not stored)."""

    station: str
    run_id: int
    files: tuple[Path, ...]  # oldest first; the last one may be under its writing name
    stored: StoredResult | None
    note: str  # "" or why the store was not the guide (no row yet, no answer)

    @property
    def writing(self) -> bool:
        return bool(self.files) and self.files[-1].name.endswith(".writing")

    def signature(self) -> tuple[tuple[str, int, int], ...]:
        """(path, size, modification time) of each file: what a cached read stands for."""
        found = []
        for path in self.files:
            try:
                stat = path.stat()
            except OSError:
                continue
            found.append((str(path), stat.st_size, stat.st_mtime_ns))
        return tuple(found)


class RunLocator:
    """The runs of the page's stations (see the module docstring)."""

    def __init__(self, stations: Sequence[StationRecordings]) -> None:
        self.stations = {station.station: station for station in stations}

    def served(self, station: str) -> StationRecordings:
        found = self.stations.get(station)
        if found is None:
            served = ", ".join(self.stations) or "none"
            raise RunRequestError(
                404, f"station {station} is not one of this page's stations ({served})"
            )
        return found

    def locate(self, station: str, run_id: int) -> LocatedRun:
        """Run ``run_id`` of ``station``'s files (RunRequestError: why not)."""
        served = self.served(station)
        note = ""
        try:
            stored = self.stored(served.store, ResultsQuery(stations=[station], run_id=run_id))
        except StoreError as err:
            stored, note = [], f"the results store did not answer ({err}): found by the folder"
        row = stored[0] if stored else None
        files = self._run_files(served, run_id)
        if not files and row is not None and row.recording and row.result.sync_id is not None:
            files = self._cycle_files(served, Path(row.recording))
        if row is not None and row.recording:
            self._check_named(served, run_id, Path(row.recording), files, row)
        elif row is None and not note:
            note = "not in the results store yet: found by the folder"
        if not files:
            where = f"no file of it in {served.folder}"
            if row is None:
                raise RunRequestError(
                    404, f"run {run_id} of {station}: not in the results store, {where}", True
                )
            raise RunRequestError(404, f"run {run_id} of {station}: {where}")
        for path in files:
            self._check_inside(served, run_id, path)
        return LocatedRun(station, run_id, tuple(files), row, note)

    def stored(self, target: StoreTarget, query: ResultsQuery) -> list[StoredResult]:
        """What ``target`` holds of ``query`` (StoreError: it cannot say)."""
        with ResultsStore(target, create=False, application=APPLICATION) as store:
            return store.find(query)

    def part_runs(self, part_id: str, limit: int) -> tuple[list[StoredResult], list[str]]:
        """The tightenings of ``part_id`` in the page's stores (each store once), newest
        first, at most ``limit``; and a line per store that did not answer."""
        found: dict[tuple[str, int], StoredResult] = {}
        errors = []
        for target in {str(s.store): s.store for s in self.stations.values()}.values():
            try:
                for row in self.stored(target, ResultsQuery(part_id=part_id, limit=limit)):
                    found.setdefault((row.result.station, row.result.run_id), row)
            except StoreError as err:
                errors.append(str(err))
        newest = sorted(
            found.values(),
            key=lambda s: (s.result.time_ns, s.result.station, s.result.run_id),
            reverse=True,
        )
        return newest[:limit], errors

    def program_runs(
        self, station: str, program_id: int, until_ns: int, limit: int
    ) -> list[StoredResult]:
        """The newest ``limit`` OK tightenings of ``program_id`` at ``station`` that ended
        before ``until_ns`` (StoreError: the store cannot say)."""
        query = ResultsQuery(
            stations=[station], program_id=program_id, until_ns=until_ns, verdict="OK", limit=limit
        )
        return self.stored(self.served(station).store, query)

    def _run_files(self, served: StationRecordings, run_id: int) -> list[Path]:
        """The run's files by the folder's layout, and one still being written, oldest first."""
        try:
            files = run_files(served.folder, served.station, run_id)
            hidden = f".{run_file_prefix(served.station, run_id)}*.mcap.writing"
            for _, day in station_days(served.folder, served.station):
                files += sorted(path for path in day.glob(hidden) if path.is_file())
        except InputError as err:
            raise RunRequestError(404, f"run {run_id} of {served.station}: {err}") from err
        return files

    def _cycle_files(self, served: StationRecordings, named: Path) -> list[Path]:
        """A multi-spindle cycle's run: the files of the run its cycle's file is named by
        (the first of its spindles' runs to start), the one the store names among them."""
        name = file_name_of(named, served.station)
        if name is None or name.run_id is None:
            return []
        return self._run_files(served, name.run_id)

    def _check_named(
        self,
        served: StationRecordings,
        run_id: int,
        named: Path,
        files: list[Path],
        row: StoredResult,
    ) -> None:
        """The file the store names is one of the run's files in the station's folder."""
        real = {_real(path) for path in files}
        if _real(named) in real or _real(writing_path(named)) in real:
            return
        where = f"run {run_id} of {served.station}: the results store names {named}"
        if not _inside(served.folder, named):
            raise RunRequestError(
                404, f"{where}, outside the station's recordings folder {served.folder}: not read"
            )
        if os.path.lexists(named):
            raise RunRequestError(
                404, f"{where}, which is not a file of the run in {served.folder}: not read"
            )
        host = f" (recorded on {row.recording_host})" if row.recording_host else ""
        raise RunRequestError(
            404,
            f"{where}{host}, which is not on this server: the retention policy may have removed it",
        )

    def _check_inside(self, served: StationRecordings, run_id: int, path: Path) -> None:
        if not _inside(served.folder, path):
            raise RunRequestError(
                404,
                f"run {run_id} of {served.station}: {path} leads outside the station's "
                f"recordings folder {served.folder} (to {_real(path)}): not read",
            )


def _real(path: Path) -> Path:
    return real_path(path)


def _inside(folder: Path, path: Path) -> bool:
    return _real(path).is_relative_to(folder)
