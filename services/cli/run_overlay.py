"""``boltwatch inspect --overlay RUN... [--cycle] [--reference RUN] [--align POINT]
[--out FILE.png]``.

A RUN is a run id (all digits, and no file of that name): its MCAP files are
found in the ``--config`` station's recordings folder (by the file's name; a
multi-spindle station's spindle run, whose cycle's file is named by the
cycle's first run, by the results store's recording of it); anything else is
the path of an MCAP file. With ``--cycle`` each RUN stands for its whole
multi-spindle cycle: every spindle's run of it, in spindle order. The runs are
read, aligned and drawn by :mod:`shared.offline.overlay`; a run that never
reaches the alignment point is drawn unaligned, with a warning line naming it; a symlink loop met in
the recordings folder is named in a warning line and skipped (the folder itself
one: one line, exit status 2).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from services.cli.command_options import check_png_target
from shared.config import AnyStation
from shared.errors import InputError
from shared.offline.overlay import (
    OverlayRun,
    build_overlay,
    find_run_files,
    parse_alignment,
    read_overlay_cycle,
    read_overlay_run,
    save_figure,
)
from shared.recordings import loop_lines

DEFAULT_TARGET = Path("overlay.png")


class RunFinder:
    """RUN arguments to runs; the station file is read once, and only for a run id."""

    def __init__(self, station_file: Path) -> None:
        self.station_file = station_file
        self._station: AnyStation | None = None
        self.loops: list[Path] = []  # symlink loops met in the recordings, each once

    def run(self, name: str) -> OverlayRun:
        files, run_id = self._files(name)
        return read_overlay_run(name, files, run_id)

    def cycle(self, name: str) -> list[OverlayRun]:
        """Every spindle's run of the multi-spindle cycle ``name`` is a run of."""
        files, run_id = self._files(name)
        return read_overlay_cycle(name, files, run_id)

    def _files(self, name: str) -> tuple[list[Path], int | None]:
        path = Path(name)
        if not (name.isdigit() and not path.exists()):
            return [path], None
        station = self._loaded()
        loops: list[Path] = []
        folder, station_id = station.recordings_folder, station.station_id
        try:
            files = find_run_files(folder, station_id, int(name), loops)
        except InputError:
            files = self._stored_recording(int(name))
            if not files:
                raise
        self.loops += [loop for loop in loops if loop not in self.loops]
        return files, int(name)

    def _stored_recording(self, run_id: int) -> list[Path]:
        """The recording the results store names for ``run_id`` of the station (a spindle's
        run is in its cycle's file, named by another run); [] when it names none."""
        from shared.results import ResultsQuery, ResultsStore, station_store

        station = self._loaded()
        try:
            with ResultsStore(station_store(station), create=False) as store:
                found = store.find(ResultsQuery(stations=[station.station_id], run_id=run_id))
        except Exception:  # no store, or one that cannot be read: the file's name was all
            return []
        return [
            Path(row.recording) for row in found if row.recording and Path(row.recording).is_file()
        ]

    def _loaded(self) -> AnyStation:
        if self._station is None:
            from shared.config import load_any_station

            self._station = load_any_station(self.station_file)
        return self._station


def run_overlay(args: argparse.Namespace) -> int:
    alignment = parse_alignment(args.align)
    target: Path = args.out or DEFAULT_TARGET
    check_png_target(target, "the overlay")
    finder = RunFinder(args.config)
    if args.cycle:
        runs = [run for name in args.overlay for run in finder.cycle(name)]
    else:
        runs = [finder.run(name) for name in args.overlay]
    reference = finder.run(args.reference) if args.reference is not None else None
    for line in loop_lines(finder.loops):
        print(f"boltwatch inspect: warning: {line}; skipped", file=sys.stderr)
    overlay = build_overlay(runs, reference, alignment)
    for run in [*runs, *([reference] if reference else [])]:
        if run.damage:
            print(
                f"boltwatch inspect: warning: {run.damage}; drew what is readable", file=sys.stderr
            )
    for series in overlay.unaligned:
        never = series.note.removeprefix("not aligned: ")
        print(
            f"boltwatch inspect: warning: run {series.run_id} {never}: drawn unaligned "
            "(dotted, from its own start)",
            file=sys.stderr,
        )
    save_figure(overlay, target)
    verdicts = ", ".join(f"{s.run_id} {s.verdict}" for s in overlay.series)
    print(
        f"wrote {target}: {len(overlay.series)} runs ({verdicts}), aligned at "
        f"{alignment.describe()} onto run {overlay.frame_run}"
    )
    return 0
