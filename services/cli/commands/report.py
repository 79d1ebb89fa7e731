"""``boltwatch report``: the quality engineer's statistics per program, as HTML and PNG.

::

    boltwatch report [--config STATION ...] [--plant P] [--line L] [--since DATE] [--until DATE]
                     [--program ID] [--tool ID] [--subgroup-size N] [--out FOLDER]
                     [--from-recordings]

Below the statistics, "Tool wear": each tool of those stations in the wear
ledger, its service forecast as of now and what wears it
(:mod:`shared.offline.report.report_wear`).

Reads the tightening results of the station files' stations that ended in the
range from the results store (:mod:`shared.results`; none there, or
``--from-recordings``: from every recording in range,
:mod:`shared.offline.report.recorded_results`), writes ``FOLDER/report.html``
(one self-contained file) and ``FOLDER/report.png``, and prints a summary.
No result in the range: one line, exit status 2. A file that cannot be read
is named on stderr and skipped; a payload or result refused is named too (the
first 20, then how many more); both are counted in the
report, which is written from the rest.
"""

from __future__ import annotations

import argparse
import sys
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
    from shared.config import AnyStation
    from shared.offline.report import RecordedResults, ResultFilter, WearPart

NAME = "report"
HELP = "statistics per program over recorded results: X̄/R charts, Cp/Cpk, NOK Pareto (HTML, PNG)"

#: the largest subgroup size of the control charts
MAX_SUBGROUP = 50


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
    parser.add_argument(
        "--plant", default=None, metavar="P", help="only the stations in plant P (station.plant)"
    )
    parser.add_argument(
        "--line", default=None, metavar="L", help="only the stations on line L (station.line)"
    )
    parser.add_argument("--program", type=result_program_id, default=None)
    parser.add_argument("--tool", type=result_tool_id, default=None)
    parser.add_argument(
        "--subgroup-size",
        type=int_in(2, MAX_SUBGROUP, "runs per subgroup"),
        default=5,
        metavar="N",
        help="runs per control-chart subgroup (default 5; X̄/R up to 10, X̄/s above)",
    )
    parser.add_argument(
        "--from-recordings",
        action="store_true",
        help="read every recording in range instead of the results store (slower; what the "
        "store is checked against)",
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
    from shared.offline.report import (
        ResultFilter,
        read_counts,
        terminal_lines,
        wear_lines,
        write_report,
    )

    stations = [load_any_station(path) for path in args.config]
    if args.plant is not None:
        stations = [loaded for loaded in stations if loaded.config.station.plant == args.plant]
    if args.line is not None:
        stations = [loaded for loaded in stations if loaded.config.station.line == args.line]
    if not stations:
        asked = " ".join(
            f"{option} {value}"
            for option, value in (("--plant", args.plant), ("--line", args.line))
            if value is not None
        )
        raise ConfigError(f"{asked}: no station of the station files is there")
    rule = ResultFilter(
        stations=[(loaded.station_id, loaded.recordings_folder) for loaded in stations],
        since=args.since,
        until=args.until,
        program_id=args.program,
        tool_id=args.tool,
    )
    read, source = _read(rule, stations[0], args.from_recordings)
    wear = _wear(stations, args.tool)
    report = write_report(rule, read, args.out, args.subgroup_size, source, wear)
    warn_left_out(NAME, report.damaged, report.skipped, report.refused)
    left_out = read_counts(read)
    print(f"{report.results} results ({source}{'; ' + left_out if left_out else ''})")
    for line in terminal_lines(report.programs):
        print(line)
    if wear is not None:
        print(f"tool wear (from {wear.ledger}, as of now):")
        for line in wear_lines(wear):
            print(f"  {line}")
    print(f"wrote {report.html_path} and {report.png_path}")
    return 0


def _wear(stations: list[AnyStation], tool_id: int | None) -> WearPart | None:
    """The tools of ``stations`` in the first one's wear ledger, forecast now against its
    threshold (``tool_id``: that tool only); None when there is no ledger (nothing recorded)."""
    import time

    from shared.offline.report import WearPart
    from shared.wear import WearLedger, joint_names, ledger_path
    from shared.wear.wear_forecast_table import tool_forecasts

    path = ledger_path(stations[0].recordings_folder)
    if not path.is_file():
        return None
    with WearLedger(path, read_only=True) as ledger:
        ids = sorted({t for s in stations for t in ledger.tool_ids(station=s.station_id)})
        chosen = [t for t in ids if tool_id is None or t == tool_id]
        tools = [ledger.tool(t, joints=joint_names(stations)) for t in chosen]
    threshold = stations[0].config.recorder.wear_service_threshold
    return WearPart(tools, tool_forecasts(tools, threshold, time.time_ns()), threshold, str(path))


def _read(
    rule: ResultFilter, first: AnyStation, from_recordings: bool
) -> tuple[RecordedResults, str]:
    """The results in range and from where, in words: the first station file's results store,
    or (none there, or ``--from-recordings``) every recording in range."""
    from shared.errors import StoreError
    from shared.offline.report import read_results, read_stored
    from shared.results import ResultsStore, station_store

    why = ""
    if not from_recordings:
        target = station_store(first)
        try:
            with ResultsStore(target, create=False) as store:
                return read_stored(store, rule), f"from the results store {target}"
        except StoreError as err:
            why = f"; {err}"

    def progress(done: int, total: int) -> None:
        if total >= 50:
            print(f"boltwatch report: read {done} of {total} files", file=sys.stderr)

    read = read_results(rule, progress)
    return read, f"from {read.files} recordings{why}"
