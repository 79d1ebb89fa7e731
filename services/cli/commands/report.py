"""``boltwatch report``: the quality engineer's statistics per program, as HTML and PNG.

::

    boltwatch report [--config STATION ...] [--since DATE] [--until DATE]
                     [--program ID] [--tool ID] [--subgroup-size N] [--out FOLDER]

Reads the tightening results of the station files' recordings that ended in
the range (:mod:`services.recorder.quality`), writes ``FOLDER/report.html``
(one self-contained file) and ``FOLDER/report.png``, and prints a summary.
No result in the range: one line, exit status 2.
"""

from __future__ import annotations

import argparse
import sys
from datetime import UTC, datetime, timedelta
from pathlib import Path

from services.cli.command_options import add_station_file_option
from shared.option_types import int_in

NAME = "report"
HELP = "statistics per program over recorded results: X̄/R charts, Cp/Cpk, NOK Pareto (HTML, PNG)"

#: the largest subgroup size of the control charts
MAX_SUBGROUP = 50


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


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Per program, over the tightening results recorded in a range: X̄/R control charts "
        "(X̄/s for subgroups above 10 runs) and histograms of final torque, angle, preload "
        "and process intensity; mean, σ, Cp and Cpk against the program's windows (a "
        "one-sided window: the Cpk of that side; no window: not computed); the NOK rate, a "
        "Pareto of NOK reasons, stop reasons and stick-slip events per run. Writes "
        "report.html (self-contained: opens without internet) and report.png."
    )
    add_station_file_option(parser, "station file(s) whose recordings to read", several=True)
    parser.add_argument(
        "--since",
        type=utc_moment,
        default=None,
        metavar="DATE",
        help="first day (YYYY-MM-DD) or moment (YYYY-MM-DDTHH:MM), UTC (default: all)",
    )
    parser.add_argument(
        "--until",
        type=utc_end,
        default=None,
        metavar="DATE",
        help="last day, included (YYYY-MM-DD), or moment, excluded; UTC (default: now)",
    )
    parser.add_argument("--program", type=int_in(0, 65535, "a program id"), default=None)
    parser.add_argument("--tool", type=int_in(0, 65535, "a tool id"), default=None)
    parser.add_argument(
        "--subgroup-size",
        type=int_in(2, MAX_SUBGROUP, "runs per subgroup"),
        default=5,
        metavar="N",
        help="runs per control-chart subgroup (default 5; X̄/R up to 10, X̄/s above)",
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=Path("report"),
        metavar="FOLDER",
        help="where report.html and report.png go (default: ./report)",
    )


def run(args: argparse.Namespace) -> int:
    from shared.config import load_any_station
    from shared.offline.report import ResultFilter, write_report

    stations = []
    for path in args.config:
        loaded = load_any_station(path)
        stations.append((loaded.station_id, loaded.recordings_folder))
    rule = ResultFilter(
        stations=stations,
        since=args.since,
        until=args.until,
        program_id=args.program,
        tool_id=args.tool,
    )

    def progress(done: int, total: int) -> None:
        if total >= 50:
            print(f"boltwatch report: read {done} of {total} files", file=sys.stderr)

    report = write_report(rule, args.out, args.subgroup_size, progress)
    for line in report.damaged:
        print(f"boltwatch report: warning: {line}; read what is readable", file=sys.stderr)
    from shared.offline.report import terminal_lines

    print(f"{report.results} results from {report.files} files")
    for line in terminal_lines(report.programs):
        print(line)
    print(f"wrote {report.html_path} and {report.png_path}")
    return 0
