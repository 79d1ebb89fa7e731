"""``boltwatch results``: find tightenings in the results store, newest first.

::

    boltwatch results [--part ID] [--station ST ...] [--plant P] [--line L] [--program P]
                      [--tool T] [--since DATE] [--until DATE] [--nok] [--limit N]
                      [--csv | --json]
                      [--config FILE ... | --recordings DIR | --database URL]
    boltwatch results rebuild [--config FILE ... | --recordings DIR] [--database URL]

The store is the station file's (``recorder.results_database``: a plant's
PostgreSQL; none: ``results.sqlite`` in its recordings folder) or
``--database``. Each row names its recording: ``boltwatch inspect FILE --run
RUN`` draws it. Nothing matching: one line on stderr, exit status 1. A
tightening whose figures cannot be a measurement is no result (the store keeps
it aside): each matching one is named on stderr, as ``report`` names it.

``rebuild`` reads the recordings of the station files (or every station
folder of ``--recordings``) into the store: a line with years of MCAP files gets its history.
A recordings folder that is a symlink loop is one line (exit status 2); a
station folder, day folder or file in it that is one is named and skipped.
Progress on stderr; stopped (Ctrl-C) and started again it goes on where it
stopped (files read whole are skipped); a result stored already is not
stored twice; one whose figures cannot be a measurement is named, counted and
kept aside, as the recorder does.
"""

from __future__ import annotations

import argparse
import dataclasses
import socket
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from services.cli.command_options import (
    add_station_file_option,
    result_program_id,
    result_tool_id,
    utc_end,
    utc_moment,
    warn_left_out,
)
from shared.errors import ConfigError
from shared.option_types import int_in

if TYPE_CHECKING:
    from shared.config import StationPlace
    from shared.results import StoreTarget

NAME = "results"
HELP = "find tightenings in the results store (by part, station, plant, line, program, tool, time)"

#: progress is told at most this often (a rebuild of years of files)
PROGRESS_INTERVAL_S = 1.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Find tightening results in the results store the line's recorder keeps, newest "
        "first: every result of a part (--part), of stations, a plant, a line, a program or a "
        "tool, in a range of time, only the NOK ones. Each row names its recording (boltwatch "
        "inspect FILE --run RUN draws it). 'boltwatch results rebuild' fills the store from "
        "existing recordings, resumable and idempotent."
    )
    parser.add_argument(
        "action", nargs="?", choices=["rebuild"], help="rebuild: read recordings into the store"
    )
    add_station_file_option(parser, "station file(s): their store and recordings", several=True)
    parser.add_argument(
        "--recordings",
        type=Path,
        default=None,
        metavar="DIR",
        help="a recordings folder instead of station files: its results.sqlite, and for "
        "rebuild every station folder in it",
    )
    parser.add_argument(
        "--database",
        default=None,
        metavar="URL",
        help="a PostgreSQL results store, postgresql://user@host/db (default: the station "
        "file's recorder.results_database, else results.sqlite in its recordings folder)",
    )
    which = parser.add_argument_group("which tightenings")
    which.add_argument("--part", default=None, metavar="ID", help="the part (VIN, work piece)")
    which.add_argument(
        "--station", action="append", default=[], metavar="ST", help="a station (repeatable)"
    )
    which.add_argument("--plant", default=None, metavar="P", help="a plant (station.plant)")
    which.add_argument("--line", default=None, metavar="L", help="a line (station.line)")
    which.add_argument("--program", type=result_program_id, default=None)
    which.add_argument("--tool", type=result_tool_id, default=None)
    which.add_argument(
        "--since",
        type=utc_moment,
        default=None,
        metavar="DATE",
        help="ended at or after: a day (YYYY-MM-DD) or moment (YYYY-MM-DDTHH:MM), UTC",
    )
    which.add_argument(
        "--until",
        type=utc_end,
        default=None,
        metavar="DATE",
        help="ended before: the last day, included (YYYY-MM-DD), or a moment, excluded; UTC",
    )
    which.add_argument("--nok", action="store_true", help="only NOK tightenings")
    which.add_argument(
        "--limit",
        type=int_in(1, 10_000_000, "a number of rows"),
        default=100,
        metavar="N",
        help="at most N rows, the newest (default 100)",
    )
    out = parser.add_mutually_exclusive_group()
    out.add_argument("--csv", action="store_true", help="CSV, every column of the store")
    out.add_argument("--json", action="store_true", help="JSON, every field with the steps")


def run(args: argparse.Namespace) -> int:
    from shared.results import ResultsQuery, ResultsStore, time_ns_of

    sources = _sources(args)
    target = _target(args, sources)
    if args.action == "rebuild":
        return _rebuild(target, sources)
    query = ResultsQuery(
        part_id=args.part,
        stations=args.station,
        plant=args.plant,
        line=args.line,
        program_id=args.program,
        tool_id=args.tool,
        since_ns=None if args.since is None else time_ns_of(args.since),
        until_ns=None if args.until is None else time_ns_of(args.until),
        verdict="NOK" if args.nok else None,
        limit=args.limit,
    )
    with ResultsStore(target, create=False) as store:
        found = store.find(query)
        total = store.count(query) if len(found) == args.limit else len(found)
        if len(found) == args.limit:  # those kept aside among the rows answered
            oldest_ns = found[-1].result.time_ns
            query = dataclasses.replace(query, since_ns=max(oldest_ns, query.since_ns or 0))
        refused = store.refused(query)
    from shared.results.results_table import format_csv, format_json, format_table

    warn_left_out(NAME, [], [], refused)

    if args.json:
        print(format_json(found))
    elif args.csv:
        sys.stdout.write(format_csv(found))
    elif found:
        print(format_table(found))
        if total > len(found):
            print(f"(the newest {len(found)} of {total}; --limit N for more)", file=sys.stderr)
    if not found:
        print("boltwatch results: no tightening matches", file=sys.stderr)
        return 1
    return 0


@dataclass(frozen=True)
class Source:
    """Recordings to read: a folder, its stations, where each is and the store they name."""

    folder: Path
    places: dict[str, StationPlace]  # station -> its plant, line and name
    database: str | None  # recorder.results_database


def _sources(args: argparse.Namespace) -> list[Source]:
    """``--recordings DIR`` (every station folder in it), else the station files."""
    from shared.config import StationPlace, load_any_station
    from shared.files import loop_text, real_path, symlink_loop
    from shared.recordings import check_walkable

    if args.recordings is not None:
        folder: Path = args.recordings
        if symlink_loop(folder) is not None:
            raise ConfigError(f"--recordings: {folder}: {loop_text(folder)}")
        if not folder.is_dir():
            raise ConfigError(f"--recordings: {folder} is not a folder")
        stations = sorted(  # a station folder that is a symlink loop: named when read
            path.name
            for path in folder.iterdir()
            if (path.is_dir() or symlink_loop(path) == path) and path.name[0] != "."
        )
        return [Source(folder, {station: StationPlace() for station in stations}, None)]

    sources: dict[Path, Source] = {}
    for path in args.config:
        station = load_any_station(path)
        folder = real_path(station.recordings_folder)
        check_walkable(folder)
        source = sources.setdefault(
            folder, Source(folder, {}, station.config.recorder.results_database)
        )
        source.places[station.station_id] = station.config.station.place
    return list(sources.values())


def _target(args: argparse.Namespace, sources: Sequence[Source]) -> StoreTarget:
    """``--database``, else the one store the sources name."""
    from shared.results import postgres_target, store_target

    if args.database is not None:
        try:
            return postgres_target(args.database)
        except ValueError as err:
            raise ConfigError(f"--database: {err}") from err
    targets = {
        str(target): target for target in (store_target(s.folder, s.database) for s in sources)
    }
    if len(targets) > 1:
        raise ConfigError(
            f"the station files name {len(targets)} results stores "
            f"({', '.join(sorted(targets))}); give one with --database"
        )
    (target,) = targets.values()
    return target


def _rebuild(target: StoreTarget, sources: Sequence[Source]) -> int:
    from shared.recordings import loop_lines
    from shared.results import ResultsStore
    from shared.results.recordings_reading import (
        FillCounts,
        fill_from_recordings,
        station_recordings,
    )

    places = {station: place for source in sources for station, place in source.places.items()}
    loops: list[Path] = []
    files = [path for s in sources for path in station_recordings(s.folder, s.places, None, loops)]
    told_s = [0.0]

    def progress(counts: FillCounts) -> None:
        now_s = time.monotonic()
        if now_s - told_s[0] >= PROGRESS_INTERVAL_S or counts.done == counts.files:
            told_s[0] = now_s
            print(
                f"boltwatch results rebuild: {counts.done} of {counts.files} recordings, "
                f"{counts.results} results ({counts.new} new)",
                file=sys.stderr,
            )

    print(f"boltwatch results rebuild: {len(files)} recordings into {target}", file=sys.stderr)
    with ResultsStore(target, application="boltwatch results rebuild") as store:
        counts = fill_from_recordings(
            store, files, places, socket.gethostname(), time.time_ns, progress
        )
    skipped = [*loop_lines(loops), *counts.skipped]
    warn_left_out("results rebuild", counts.damaged, skipped, counts.refused)
    before = counts.files - counts.read - len(counts.skipped)
    left_out = [
        f"{len(lines)} {what}"
        for lines, what in ((skipped, "not readable, skipped"), (counts.refused, "refused"))
        if lines
    ]
    print(
        f"read {counts.read} of {counts.files} recordings ({before} read before, unchanged"
        f"{''.join('; ' + text for text in left_out)}): {counts.results} results, "
        f"{counts.new} new to {target}"
    )
    return 0
