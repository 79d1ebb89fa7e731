"""Where ``boltwatch import`` puts runs: the recordings folder, or trace CSVs in a folder.

Both write each run whole or not at all (a temporary name in the same
folder, renamed when complete) and print one line per run. The destination
folder is made, or refused with one line (a file in its place, a file on
its way, no permission), before any run is read.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING

from shared import files
from shared.errors import InputError

if TYPE_CHECKING:
    from shared.offline.controller_import import ControllerRun
    from shared.recordings.rerun import RerunOptions


def make_folder(folder: Path, what: str) -> Path:
    """``folder``, made if missing; InputError naming it, what it is for, and why not."""
    try:
        return files.make_folder(folder)
    except files.FolderError as err:
        raise InputError(f"{folder}: {what}: {err}") from err


def write_csv_whole(target: Path, rows: Iterable[tuple[float, float, float, float | None]]) -> int:
    """:func:`shared.contract.trace.write_trace` under a temporary name, renamed when complete."""
    from shared.contract import write_trace
    from shared.offline.controller_import import remove_temporary, temporary_path

    temporary = temporary_path(target)
    try:
        count = write_trace(temporary, rows)
        os.replace(temporary, target)
    except OSError as err:
        remove_temporary([temporary])
        # a person looks for the file the run was going to, not for a hidden one that is gone
        raise OSError(err.errno, err.strerror, os.fspath(target)) from err
    except BaseException:
        remove_temporary([temporary])
        raise
    return count


class CsvWriter:
    """Each run as ``<folder>/<source stem>.csv``, time from its first sample."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder

    def write(self, run: ControllerRun) -> bool:
        """Write the run's trace; True (a CSV is always written, over an older one)."""
        from shared.files import describe_os_error
        from shared.offline.controller_import import RunNotWrittenError

        target = self.folder / f"{run.source.stem}.csv"
        rows = zip(run.run_time_s, run.torque_nm, run.angle_deg, [None] * len(run), strict=True)
        try:
            count = write_csv_whole(target, rows)
        except OSError as err:
            raise RunNotWrittenError(describe_os_error(err, target)) from err
        print(f"{run.source} -> {target} ({count} samples)")
        return True

    def __enter__(self) -> CsvWriter:
        return self

    def __exit__(self, *_exc: object) -> None:
        pass


class RecordingsWriter:
    """Each run into the recordings folder, with its predictor replay and wear-ledger count."""

    def __init__(self, folder: Path, station: str, rerun: bool) -> None:
        from shared.wear import WearLedger, ledger_path

        self.folder = folder
        self._station = station
        self._options: RerunOptions | None = None
        if rerun:
            from shared.recordings.rerun import RerunOptions

            self._options = RerunOptions()
        self._ledger = WearLedger(ledger_path(folder))

    def write(self, run: ControllerRun) -> bool:
        """Import the run; True when written now, False when it was already there."""
        from shared.offline.controller_import import import_run

        imported = import_run(run, self.folder, self._station, self._options, self._ledger)
        summary = imported.summary
        if imported.mcap is None or summary is None:
            print(f"{run.source}: run {run.run_id} already in {imported.existing}, skipped")
            return False
        extra = f" + {imported.rrd.name}" if imported.rrd is not None else ""
        replaced = "".join(f"; replaced the unfinished {path.name}" for path in imported.replaced)
        what = "a loosening, " if summary.operation == "loosening" else ""
        print(
            f"{run.source} -> {imported.mcap}{extra} ({what}{imported.samples} samples, "
            f"{summary.events} events, I_process {summary.process_intensity:.3g}{replaced})"
        )
        return True

    def __enter__(self) -> RecordingsWriter:
        return self

    def __exit__(self, *_exc: object) -> None:
        self._ledger.close()
