"""Command-line options that several ``boltwatch`` commands share.

Defined once so that an option reads, defaults and resolves the same in every
command that takes it:

- ``RUN.mcap`` and ``--run ID`` (export, inspect): one run of one recording;
  a damaged recording (recorder killed) is read as far as it goes, with a
  one-line warning on stderr instead of an error;
- ``--config FILE`` (one or several): the station file(s), by default
  ``config/station.toml``;
- ``--recordings DIR`` and ``--config FILE`` (wear, import): the recordings
  folder, by default the station file's ``recorder.folder``;
- ``--since`` / ``--until`` (report, results): moments in UTC, a bare date a whole day;
- ``--program`` / ``--tool`` (report, results): any id a result may carry
  (:data:`RESULT_ID_MAX`), so what the store holds can be asked for;
- a PNG to draw (inspect ``--out``, model ``--plot``/``--out``): checked
  before the work, see :func:`check_png_target`.

Light imports only: every command module imports this for ``boltwatch --help``.
"""

from __future__ import annotations

import argparse
import errno
import os
import sys
from datetime import UTC, datetime, timedelta
from pathlib import Path

from shared.errors import InputError
from shared.option_types import int_in

#: The station file a command reads when none is given.
DEFAULT_STATION_FILE = Path("config/station.toml")
#: the largest program or tool id a result may carry: the contract's (64 signed bits,
#: ``shared.contract.INT64_MAX``; a controller's, imported, may be that wide)
RESULT_ID_MAX = 2**63 - 1
#: ``--program ID`` and ``--tool ID`` of a command that asks for results
result_program_id = int_in(0, RESULT_ID_MAX, "a program id")
result_tool_id = int_in(0, RESULT_ID_MAX, "a tool id")


def add_recording_argument(parser: argparse.ArgumentParser) -> None:
    """The positional ``RUN.mcap``: the recording to read (``args.recording``)."""
    parser.add_argument("recording", type=Path, metavar="RUN.mcap", help="the recording")


def add_run_option(parser: argparse.ArgumentParser, help_text: str) -> None:
    """``--run ID`` (``args.run``, None when not given): which run of the recording."""
    parser.add_argument("--run", type=int, default=None, metavar="ID", help=help_text)


def warn_damaged_recording(command: str, state: str, what_was_done: str) -> None:
    """Say on stderr that the recording was damaged and what was still done with it."""
    print(f"boltwatch {command}: warning: {state}; {what_was_done}", file=sys.stderr)


#: refused payloads and results named one by one on stderr; the rest are counted
REFUSED_LINES = 20


def warn_left_out(command: str, damaged: list[str], skipped: list[str], refused: list[str]) -> None:
    """On stderr, what a reading of recordings left out: each damaged file and each file
    skipped, the first :data:`REFUSED_LINES` payloads or results refused and how many more."""
    warning = f"boltwatch {command}: warning:"
    for line in damaged:
        print(f"{warning} {line}; read what is readable", file=sys.stderr)
    for line in skipped:
        print(f"{warning} {line}; skipped", file=sys.stderr)
    for line in refused[:REFUSED_LINES]:
        print(f"{warning} refused {line}", file=sys.stderr)
    if len(refused) > REFUSED_LINES:
        print(f"{warning} {len(refused) - REFUSED_LINES} more refused", file=sys.stderr)


def add_station_file_option(
    parser: argparse.ArgumentParser | argparse._ArgumentGroup,
    help_text: str = "station file",
    several: bool = False,
) -> None:
    """``--config FILE`` (``several``: one or more, a list) defaulting to the station file."""
    default_help = f"{help_text} (default: {DEFAULT_STATION_FILE})"
    if several:
        parser.add_argument(
            "--config",
            type=Path,
            nargs="+",
            default=[DEFAULT_STATION_FILE],
            metavar="FILE",
            help=default_help,
        )
    else:
        parser.add_argument("--config", type=Path, default=DEFAULT_STATION_FILE, help=default_help)


def add_recordings_folder_options(
    parser: argparse.ArgumentParser, folder_help: str = "recordings folder"
) -> None:
    """``--recordings DIR`` and ``--config FILE``; :func:`recordings_folder` resolves them."""
    parser.add_argument(
        "--recordings",
        type=Path,
        default=None,
        metavar="DIR",
        help=f"{folder_help} (default: the station file's recorder.folder)",
    )
    add_station_file_option(parser, "station file, for its recorder.folder")


def recordings_folder(args: argparse.Namespace) -> Path:
    """``--recordings`` if given, else the ``recorder.folder`` of the ``--config`` station file.

    The station file is read only when needed: with ``--recordings`` a missing
    or broken station file is no error.
    """
    if args.recordings is not None:
        folder: Path = args.recordings
        return folder
    from shared.config import load_any_station

    return load_any_station(args.config).recordings_folder


def check_png_target(path: Path, what: str) -> None:
    """A picture is written as PNG, into a folder that exists: say so before drawing it
    (a bad folder is the OSError that writing would meet, told as every command tells it)."""
    if path.suffix.lower() != ".png":
        raise InputError(f"{path}: {what} is written as PNG; give a path ending in .png")
    if not path.parent.is_dir():
        code = errno.ENOTDIR if path.parent.exists() else errno.ENOENT
        raise OSError(code, os.strerror(code), str(path))


def utc_moment(text: str) -> datetime:
    """``2026-03-01`` (that day, 00:00 UTC) or ``2026-03-01T14:30`` (UTC unless an offset is
    given): an argparse type."""
    try:
        moment = datetime.fromisoformat(text)
    except ValueError as err:
        raise argparse.ArgumentTypeError(
            f"expected a date YYYY-MM-DD or a time YYYY-MM-DDTHH:MM (UTC), got {text!r}"
        ) from err
    return moment.replace(tzinfo=UTC) if moment.tzinfo is None else moment.astimezone(UTC)


def utc_end(text: str) -> datetime:
    """Like :func:`utc_moment`, but a bare date means the end of that day (it is included)."""
    moment = utc_moment(text)
    return moment + timedelta(days=1) if len(text.strip()) == len("YYYY-MM-DD") else moment
