"""Where a run's files go, and how they are found again: the one rule of a recordings folder.

Layout (UTC)::

    <recordings>/<station>/<YYYY-MM-DD>/<station>_run<run_id>_<HHMMSS>[_part<N>][_<copy>].mcap
    <recordings>/<station>/<YYYY-MM-DD>/<station>_idle_<HHMMSS>.mcap   between runs, before the first
    ... and beside a run's .mcap its Rerun recording, the same stem with .rrd

While the recorder writes a run's file it is named ``.<name>.writing`` (hidden,
and no ``.mcap``: no reader of the folder takes it for a run file) and renamed
to ``<name>`` when it is complete (:func:`writing_path`, :func:`unfinished_files`:
what a crash left, which the recorder finishes at its next start).

``<station>`` is the station id made safe for a file name (anything but
letters, digits, ``_`` and ``-`` becomes ``_``): station ids are key-expression
safe already, so this changes nothing of a valid id. ``part`` counts the
files of one run past the recorder's size or duration limit; ``copy`` a name
taken already. Every writer (the recorder, ``boltwatch import``) names its
files with :func:`file_path`, every reader (``inspect``, ``report``, the
overlay, the import's look for a run it did already, the retention policy)
finds them with the functions below; only regular files are ever returned. A
folder to walk that is a symbolic link that never ends (to itself, round a
circle) is one line (:func:`check_walkable`); such a link inside it is skipped
and told to the caller (``loops``), to be named (:func:`loop_lines`).
:func:`file_name_of` reads a file's name back: its run, when it was opened,
its part and copy.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass
from datetime import UTC, date, datetime
from pathlib import Path
from typing import Final

from shared.errors import InputError
from shared.files import SYMLINK_LOOP, loop_text, symlink_loop

#: what a station id may hold in a file name; anything else becomes "_"
_UNSAFE: Final = re.compile(r"[^A-Za-z0-9_-]")
MCAP_SUFFIX: Final = ".mcap"
RERUN_SUFFIX: Final = ".rrd"
#: the end of the name a recorder's run file has until it is complete
WRITING_SUFFIX: Final = ".writing"


def station_folder_name(station: str) -> str:
    """The station's folder (and file name prefix): its id made safe for a file name."""
    return _UNSAFE.sub("_", station) or "_"


def file_path(
    folder: Path,
    station: str,
    run_id: int | None,
    opened_ns: int,
    part: int = 1,
    unique: bool = True,
) -> Path:
    """Where a file opened at ``opened_ns`` goes; never an existing file (``unique=False``:
    the name it would have in an empty folder, existing or not)."""
    opened = datetime.fromtimestamp(opened_ns / 1e9, UTC)
    safe_station = station_folder_name(station)
    label = "idle" if run_id is None else f"run{run_id}"
    stem = f"{safe_station}_{label}_{opened:%H%M%S}"
    if part > 1:
        stem += f"_part{part}"
    day = folder / safe_station / f"{opened:%Y-%m-%d}"
    path = day / f"{stem}{MCAP_SUFFIX}"
    copy = 2
    while unique and (path.exists() or writing_path(path).exists()):
        path = day / f"{stem}_{copy}{MCAP_SUFFIX}"
        copy += 1
    return path


def writing_path(final: Path) -> Path:
    """The name a file has while it is written (same folder): ``.<name>.writing``."""
    return final.with_name(f".{final.name}{WRITING_SUFFIX}")


def final_path_of(writing: Path) -> Path | None:
    """The name a file written as ``writing`` takes when complete (None: not such a name)."""
    name = writing.name
    if not (name.startswith(".") and name.endswith(MCAP_SUFFIX + WRITING_SUFFIX)):
        return None
    return writing.with_name(name[1 : -len(WRITING_SUFFIX)])


def unfinished_files(folder: Path) -> list[Path]:
    """The files under ``folder`` (``<station>/<day>/``) still under their writing name,
    regular files only, in name order: being written, or left so by a crash."""
    pattern = f"*/*/.*{MCAP_SUFFIX}{WRITING_SUFFIX}"
    return sorted(path for path in folder.glob(pattern) if path.is_file())


def run_file_prefix(station: str, run_id: int) -> str:
    """The start of every file name of run ``run_id`` of ``station`` (any part, any copy)."""
    return f"{station_folder_name(station)}_run{run_id}_"


def rerun_path(mcap: Path) -> Path:
    """The Rerun recording beside a run's MCAP file."""
    return mcap.with_suffix(RERUN_SUFFIX)


def check_walkable(folder: Path) -> None:
    """InputError (one line: the folder, and that it is a symlink loop) when ``folder``, or a
    link on the way to it, is a symbolic link that never ends: nothing in it can be read."""
    if symlink_loop(folder) is not None:
        raise InputError(f"{folder}: {loop_text(folder)}")


def station_days(
    folder: Path, station: str, loops: list[Path] | None = None
) -> Iterator[tuple[date, Path]]:
    """The day folders of ``station`` under ``folder``, oldest first. ``folder`` a symlink
    loop: InputError (:func:`check_walkable`); the station's folder or a day folder one:
    skipped, put in ``loops``."""
    check_walkable(folder)
    base = folder / station_folder_name(station)
    if not base.is_dir():
        _note_loop(base, loops)
        return
    for day in sorted(base.iterdir()):
        try:
            day_date = date.fromisoformat(day.name)
        except ValueError:
            continue
        if day.is_dir():
            yield day_date, day
        else:
            _note_loop(day, loops)


def recording_files(day: Path, prefix: str = "", loops: list[Path] | None = None) -> list[Path]:
    """The MCAP files of one day folder whose name starts with ``prefix``, in name order; one
    that is a symlink loop is put in ``loops``."""
    files = []
    for path in sorted(day.glob(f"{glob_escape(prefix)}*{MCAP_SUFFIX}")):
        if path.is_file():
            files.append(path)
        else:
            _note_loop(path, loops)
    return files


def run_files(
    folder: Path, station: str, run_id: int, loops: list[Path] | None = None
) -> list[Path]:
    """Every MCAP file of run ``run_id`` of ``station``, in any day folder, oldest first
    (symlink loops met: in ``loops``, as :func:`station_days` says)."""
    prefix = run_file_prefix(station, run_id)
    return [
        path
        for _, day in station_days(folder, station, loops)
        for path in recording_files(day, prefix, loops)
    ]


def loop_lines(loops: list[Path]) -> list[str]:
    """A line naming each of ``loops`` (what a command skipped: it is a symlink loop)."""
    return [f"{path}: {SYMLINK_LOOP}" for path in loops]


def _note_loop(path: Path, loops: list[Path] | None) -> None:
    """Put ``path`` in ``loops`` when it is a symlink loop itself."""
    if loops is not None and symlink_loop(path) == path:
        loops.append(path)


@dataclass(frozen=True, slots=True)
class FileName:
    """What a recording's name says: :func:`file_path` read back."""

    run_id: int | None  # None: an idle file (between runs, before the station's first)
    opened: datetime  # UTC, to the second: its day folder and ``HHMMSS``
    part: int  # 1, or N of ``_part<N>``
    copy: int  # 1, or N of ``_<N>`` (a name taken already)

    @property
    def order(self) -> tuple[datetime, int, int]:
        """Sorts a station's files in the order they were opened."""
        return self.opened, self.part, self.copy


def file_name_of(path: Path, station: str) -> FileName | None:
    """What the name of ``path`` (in a day folder of ``station``) says; None: not a name
    :func:`file_path` gives."""
    safe_station = re.escape(station_folder_name(station))
    found = re.fullmatch(
        rf"{safe_station}_(?:idle|run(?P<run>\d+))_(?P<time>\d{{6}})"
        rf"(?:_part(?P<part>\d+))?(?:_(?P<copy>\d+))?{re.escape(MCAP_SUFFIX)}",
        path.name,
    )
    if found is None:
        return None
    try:
        opened = datetime.strptime(f"{path.parent.name} {found['time']}", "%Y-%m-%d %H%M%S")
    except ValueError:
        return None
    return FileName(
        run_id=None if found["run"] is None else int(found["run"]),
        opened=opened.replace(tzinfo=UTC),
        part=int(found["part"] or 1),
        copy=int(found["copy"] or 1),
    )


def glob_escape(text: str) -> str:
    """``text`` as a literal in a glob pattern (a station id never needs it; a prefix may)."""
    return re.sub(r"([*?\[])", r"[\1]", text)
