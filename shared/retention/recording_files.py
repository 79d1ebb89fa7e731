"""The recordings a retention policy looks at: each run file of the stations, with its size,
when it was last written, and whether it may be touched at all.

A run file is its ``.mcap`` and the Rerun ``.rrd`` beside it (one decision,
both go). Never touched, whatever the rules say (:attr:`RecordingFile.protected`):

- a file the recorder has open (it says which: ``open_paths``);
- the newest file of each station, by the time its name says it was opened:
  the recorder's current file, even idle for a weekend, when the command is
  run beside a recorder it cannot ask;
- a file written in the last :data:`RECENT_NS` (a file the recorder opened
  since it said which it had open; what a station's spool sends again).
"""

from __future__ import annotations

from collections.abc import Collection, Iterable
from dataclasses import dataclass, replace
from pathlib import Path

from shared.recordings import FileName, file_name_of, recording_files, rerun_path, station_days

#: a file written this recently is never touched (nanoseconds: an hour)
RECENT_NS = 3600 * 1_000_000_000

OPEN = "open by the recorder"
NEWEST = "the newest of its station"
RECENT = "written in the last hour"


@dataclass(frozen=True, slots=True)
class RecordingFile:
    """One run file: its ``.mcap`` (and the ``.rrd`` beside, when there is one)."""

    path: Path  # the .mcap
    station: str
    run_id: int | None  # the run its name names; None: an idle file, or a name of no run
    size_bytes: int  # the .mcap and .rrd together
    disk_bytes: int  # what deleting them frees on the disk (the blocks they hold)
    modified_ns: int  # when the newer of the two was last written
    protected: str | None = None  # why it is never touched now; None: the rules decide

    @property
    def rerun(self) -> Path:
        return rerun_path(self.path)


def list_recordings(
    folder: Path,
    stations: Iterable[str],
    now_ns: int,
    open_paths: Collection[Path] = (),
    loops: list[Path] | None = None,
) -> list[RecordingFile]:
    """Every run file of ``stations`` under ``folder``, oldest day first; a file gone while
    it is listed (deleted by a person, another pass) is left out; a symlink loop met on the
    way (never touched) is put in ``loops`` (``folder`` one: InputError)."""
    opened = set()  # the open files by (device, inode): whatever path names them
    for path in open_paths:
        try:
            stat = path.stat()
        except FileNotFoundError:
            continue
        opened.add((stat.st_dev, stat.st_ino))
    found: list[RecordingFile] = []
    for station in stations:
        named: list[tuple[RecordingFile, FileName | None]] = []
        for _, day in station_days(folder, station, loops):
            for path in recording_files(day, loops=loops):
                name = file_name_of(path, station)
                recording = _recording(path, station, name, now_ns, opened)
                if recording is not None:
                    named.append((recording, name))
        orders = [(name.order, i) for i, (_, name) in enumerate(named) if name is not None]
        newest = max(orders)[1] if orders else None
        for i, (recording, _) in enumerate(named):
            is_newest = i == newest and recording.protected is None
            found.append(replace(recording, protected=NEWEST) if is_newest else recording)
    return found


def _recording(
    path: Path,
    station: str,
    name: FileName | None,
    now_ns: int,
    opened: Collection[tuple[int, int]],
) -> RecordingFile | None:
    try:
        stat = path.stat()
    except FileNotFoundError:
        return None
    size, disk, modified = stat.st_size, stat.st_blocks * 512, stat.st_mtime_ns
    try:
        rerun = rerun_path(path).stat()
    except FileNotFoundError:
        pass
    else:
        size, disk = size + rerun.st_size, disk + rerun.st_blocks * 512
        modified = max(modified, rerun.st_mtime_ns)
    protected = None
    if (stat.st_dev, stat.st_ino) in opened:
        protected = OPEN
    elif now_ns - modified < RECENT_NS:
        protected = RECENT
    return RecordingFile(
        path=path,
        station=station,
        run_id=None if name is None else name.run_id,
        size_bytes=size,
        disk_bytes=disk,
        modified_ns=modified,
        protected=protected,
    )
