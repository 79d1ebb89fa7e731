"""``boltwatch import CONTROLLER.json...``: real controller runs into the recordings.

Reads the JSON runs a Bosch Rexroth CS351 controller exports (one file per
run, see :mod:`shared.offline.controller_import.controller_run`) and writes each as a live
recording would be: ``<recordings>/<station>/<YYYY-MM-DD>/<station>_run<id>_<HHMMSS>.mcap``
(+ ``.rrd``), same channels, schemas and metadata, the controller's own
timing kept, the controller's result on ``boltwatch/<st>/controller``, and
the predictor's replay of the run (:mod:`shared.offline.controller_import.controller_replay`):
its events, intensity, advisory decision and run summary. Each run is
counted in the wear ledger under the controller's tool serial, once. A
loosening (every step turning the tool back) is recorded as one: no
tightening result, its summary and metadata say so, and the ledger adds its
intensity to the tool but not to its tightenings.
``--csv DIR`` writes offline trace CSVs instead (header
``time_s,torque_nm,angle_deg,force_n``, force empty, time from the run's
first sample, like ``boltwatch export``) for ``boltwatch predict``.

Every input is tried, one at a time: a bad file is one line on stderr naming
the file and what is wrong, the others are still imported, and the last line
counts what was imported, already there, refused (bad input) and not written
(the disk). The exit status is 2 when any was refused or not written. Each
run is written whole or not at all.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

from services.cli.command_options import add_recordings_folder_options, recordings_folder

NAME = "import"
HELP = "import tightening-controller JSON runs (CS351) as recordings (MCAP), or trace CSVs"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Write each controller run into the recordings folder exactly as the recorder "
        "writes a live run (MCAP with JSON schemas, metadata, a Rerun .rrd beside it), "
        "under the station --station and the date of the run, keeping the controller's "
        "timing (about 833 Hz, repeated timestamps and gaps as recorded) and its result "
        "(OK/NOK, each step's nominal and actual values). The predictor is replayed over "
        "each run (torque only, to the last step's torque target): its events, intensity "
        "and the stop it would have decided are recorded, marked as a replay, and the run "
        "counts in the wear ledger under the controller's tool serial, once. A loosening "
        "(every step at a negative speed) is recorded as a loosening: no tightening result, "
        "its intensity in the tool's wear but not among its tightenings. A run already "
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


@dataclass(slots=True)
class Tally:
    """What became of the inputs."""

    inputs: int
    imported: int = 0
    already_there: int = 0
    refused: int = 0  # bad input: the file says what is wrong
    not_written: int = 0  # good input that could not be written (disk, folder)

    def line(self, where: Path, csv: bool) -> str:
        what = "runs as trace CSVs" if csv else "runs"
        line = f"imported {self.imported} of {self.inputs} {what} into {where}"
        if not csv:
            line += f", {self.already_there} already there"
        line += f", {self.refused} refused"
        if self.not_written:
            line += f", {self.not_written} not written"
        return line


def run(args: argparse.Namespace) -> int:
    from services.cli.import_destination import CsvWriter, RecordingsWriter, make_folder
    from shared.errors import BoltwatchError, InputError
    from shared.offline.controller_import import (
        DEFAULT_STATION,
        check_station_id,
        read_controller_run,
    )
    from shared.wear import RefusedSummaryError

    tally = Tally(len(args.runs))
    writer: CsvWriter | RecordingsWriter
    if args.csv_dir is not None:
        writer = CsvWriter(make_folder(args.csv_dir, "--csv"))
    else:
        station = check_station_id(args.station or DEFAULT_STATION)
        folder = make_folder(recordings_folder(args), "recordings folder")
        writer = RecordingsWriter(folder, station, rerun=not args.no_rerun)
    with writer:
        for path in args.runs:
            try:
                controller_run = read_controller_run(path)
            except InputError as err:
                _error(str(err))
                tally.refused += 1
                continue
            try:
                done = writer.write(controller_run)
            except RefusedSummaryError as err:  # the replay's figures: bad input, not the disk
                _error(f"{path}: refused: {err}")
                tally.refused += 1
                continue
            except BoltwatchError as err:
                _error(f"{path}: not written: {err}")
                tally.not_written += 1
                continue
            except Exception as err:  # a fault of ours must not stop the batch either
                _error(f"{path}: not written: internal error {type(err).__name__}: {err}")
                tally.not_written += 1
                continue
            if done:
                tally.imported += 1
            else:
                tally.already_there += 1
    print(tally.line(writer.folder, csv=args.csv_dir is not None))
    return 2 if tally.refused or tally.not_written else 0


def _error(line: str) -> None:
    print(f"boltwatch import: {line}", file=sys.stderr)
