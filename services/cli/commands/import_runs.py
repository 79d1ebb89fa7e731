"""``boltwatch import CONTROLLER.json...``: real controller runs into the recordings.

Reads the JSON runs a Bosch Rexroth CS351 controller exports (one file per
run, see :mod:`services.recorder.controller_run`) and writes each as a live
recording would be: ``<recordings>/<station>/<YYYY-MM-DD>/<station>_run<id>_<HHMMSS>.mcap``
(+ ``.rrd``), same channels, schemas and metadata, the controller's own
timing kept. ``--csv DIR`` writes offline trace CSVs instead (header
``time_s,torque_nm,angle_deg,force_n``, force empty) for ``boltwatch predict``.

Every input is tried: a bad file is one line on stderr naming the file and
what is wrong, the good ones are still imported, and the exit status is 2
when any failed.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from services.cli.command_options import add_recordings_folder_options, recordings_folder

if TYPE_CHECKING:
    from services.recorder.controller_run import ControllerRun

NAME = "import"
HELP = "import tightening-controller JSON runs (CS351) as recordings (MCAP), or trace CSVs"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Write each controller run into the recordings folder exactly as the recorder "
        "writes a live run (MCAP with JSON schemas, metadata, a Rerun .rrd beside it), "
        "under the station --station and the date of the run, keeping the controller's "
        "timing (about 833 Hz, repeated timestamps and gaps as recorded). A run already "
        "in the folder is skipped. With --csv DIR, write trace CSVs for 'boltwatch predict' "
        "instead. Bad files are reported one line each; the rest are still imported."
    )
    parser.add_argument("runs", type=Path, nargs="+", metavar="CONTROLLER.json", help="run files")
    parser.add_argument(
        "--station",
        default=None,
        metavar="ID",
        help="station id the runs are filed under (default: cs351)",
    )
    add_recordings_folder_options(parser)
    parser.add_argument("--no-rerun", action="store_true", help="MCAP only, no .rrd beside it")
    parser.add_argument(
        "--csv",
        "--out-dir",
        dest="csv_dir",
        type=Path,
        default=None,
        metavar="DIR",
        help="write trace CSVs into DIR instead of recordings",
    )


def run(args: argparse.Namespace) -> int:
    from services.recorder.controller_import import DEFAULT_STATION, check_station_id
    from services.recorder.controller_run import read_controller_run
    from shared.errors import InputError

    good: list[ControllerRun] = []
    failed = 0
    for path in args.runs:
        try:
            good.append(read_controller_run(path))
        except InputError as err:
            print(f"boltwatch import: {err}", file=sys.stderr)
            failed += 1
    if args.csv_dir is not None:
        written = _write_csv(good, args.csv_dir)
        where = args.csv_dir
    else:
        station = check_station_id(args.station or DEFAULT_STATION)
        recordings = recordings_folder(args)
        written, write_failed = _write_recordings(good, recordings, station, not args.no_rerun)
        failed += write_failed
        where = recordings
    total = len(args.runs)
    print(
        f"imported {written} of {total} runs into {where}"
        + (f"; {failed} failed" if failed else "")
    )
    return 2 if failed else 0


def _write_csv(runs: list[ControllerRun], out_dir: Path) -> int:
    from shared.trace import write_trace

    out_dir.mkdir(parents=True, exist_ok=True)
    for run in runs:
        target = out_dir / f"{run.source.stem}.csv"
        rows = zip(run.time_s, run.torque_nm, run.angle_deg, [None] * len(run), strict=True)
        count = write_trace(target, rows)
        print(f"{run.source} -> {target} ({count} samples)")
    return len(runs)


def _write_recordings(
    runs: list[ControllerRun], recordings: Path, station: str, rerun: bool
) -> tuple[int, int]:
    """(runs written or already there, runs that could not be written)."""
    from services.recorder.controller_import import import_run

    options = None
    if rerun and runs:
        from services.recorder.rerun_sink import RerunOptions

        options = RerunOptions()
    done = failed = 0
    for run in runs:
        try:
            imported = import_run(run, recordings, station, options)
        except OSError as err:
            print(f"boltwatch import: {run.source}: cannot write into {recordings}: {err}",
                  file=sys.stderr)  # fmt: skip
            failed += 1
            continue
        done += 1
        if imported.mcap is None:
            print(f"{run.source}: run {run.run_id} already in {imported.existing}, skipped")
        else:
            extra = f" + {imported.rrd.name}" if imported.rrd is not None else ""
            print(f"{run.source} -> {imported.mcap}{extra} ({imported.samples} samples)")
    return done, failed
