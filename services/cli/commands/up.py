"""``boltwatch up``: the whole simulated station, end to end, with a table at the end.

Starts the line's zenoh router and the station's services as separate
processes (recorder, predictor, acquisition, then the simulated rig), waits
until every service shows its liveliness token, lets the rig tighten
``--runs`` joints, prints one row per run as it ends, then stops everything
in order and prints the table, the bus counters and where the recordings are.
A service that dies is reported with the end of its log, and the rest stop.

``--controller openprotocol`` runs the station without CAN: the rig is an
Open Protocol controller (a TCP server on the station file's ``[openprotocol]``
host:port, ``serve rig --controller openprotocol``) and the bridge (``serve
openprotocol``) connects to it instead of an acquisition and a predictor; the
predictor replays each run after the fact inside the bridge. A station file
without an ``[openprotocol]`` section gets one for the simulated controller on
this machine (127.0.0.1:4545, a derived file in the run's log folder). The first
tightening waits until the bridge has subscribed to results (the operator waits
for the line), the others keep the tool's pace.

``--spindles N`` makes the station a multi-spindle system of N spindles (a
derived station file with ``[station] spindles = N`` in the run's log
folder): each of the ``--runs`` is a synchronised cycle of every spindle, one
part per cycle, each spindle's run its own row with its spindle number, and
the totals say how many cycles were OK. With ``--controller openprotocol``
the simulated controller is the multi-spindle system.

``--stations N`` runs a line of N simulated stations on one router: N
station files derived from ``--config`` (ids ``st1..stN`` when the base id is
``st1``, each with its own CAN multicast port, tool id and rig seed; see
:mod:`shared.config.line`) are written into the run's log folder; ONE
recorder and ONE predictor serve them all, each station has its own
acquisition and rig. The exit status is 0 only if every station got all
its runs.
"""

from __future__ import annotations

import argparse
import signal
import sys
import time
from datetime import UTC, datetime
from pathlib import Path
from types import FrameType

from services.cli.command_options import add_station_file_option
from shared.option_types import seconds

NAME = "up"
HELP = "run the simulated station (or --stations N) end to end: rig, acquisition, predictor, ..."


class StoppedBySignalError(Exception):
    """SIGTERM or SIGHUP reached ``boltwatch up``."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_station_file_option(parser)
    parser.add_argument(
        "--runs", type=int, default=5, help="tightenings to run per station (default 5)"
    )
    parser.add_argument(
        "--stations",
        type=int,
        default=1,
        help="simulated stations on the line, derived from --config (default 1)",
    )
    parser.add_argument(
        "--program", type=int, default=None, help="program id (default: the first program)"
    )
    parser.add_argument(
        "--spindles",
        type=int,
        default=None,
        help="a multi-spindle station of N spindles tightening one part per cycle; each of "
        "--runs is a cycle of every spindle (default: the station file's [station] spindles, 1)",
    )
    parser.add_argument(
        "--controller",
        choices=("can", "openprotocol"),
        default="can",
        help="can: rig and acquisition on a CAN bus (default); openprotocol: the rig as an "
        "Open Protocol controller on the station's [openprotocol] host:port and the bridge",
    )
    parser.add_argument(
        "--startup-timeout-s",
        type=seconds,
        default=60.0,
        help="how long services may take to come up (default 60 s)",
    )


def with_local_controller(config: Path, folder: Path) -> Path:
    """A copy of the station file ``config`` (paths made absolute) with the section of the
    simulated controller on this machine, ``[openprotocol] host = "127.0.0.1"`` (port 4545):
    for a station file that has no ``[openprotocol]`` section of its own."""
    from shared.config import derive_stations

    (path,) = derive_stations(config, 1, folder)
    path.write_text(
        path.read_text() + "\n# boltwatch up --controller openprotocol: the simulated "
        'controller on this machine\n[openprotocol]\nhost = "127.0.0.1"\n'
    )
    return path


def with_spindles(config: Path, folder: Path, spindles: int) -> Path:
    """A copy of the station file ``config`` (paths made absolute) whose station has
    ``spindles`` spindles (``[station] spindles``)."""
    from shared.config import derive_stations, load_station
    from shared.config.loading import read_toml
    from shared.config.toml_writer import dumps

    (path,) = derive_stations(config, 1, folder)
    document = read_toml(path)
    document["station"] = {**document["station"], "spindles": spindles}
    path.write_text(
        f"# Derived by boltwatch up --spindles {spindles} from {config.resolve()}\n"
        + dumps(document)
    )
    load_station(path)  # its spindles' CAN ids and tools, checked now
    return path


def _check_counts(args: argparse.Namespace) -> None:
    """--runs, --stations and --spindles each within bounds, and together what ``up`` runs."""
    from shared.contract import MAX_SPINDLES
    from shared.errors import ConfigError

    if args.runs < 1:
        raise ConfigError(f"--runs must be at least 1 (got {args.runs})")
    if args.stations < 1:
        raise ConfigError(f"--stations must be at least 1 (got {args.stations})")
    if args.spindles is not None and not 1 <= args.spindles <= MAX_SPINDLES:
        raise ConfigError(f"--spindles must be 1 to {MAX_SPINDLES} (got {args.spindles})")
    if args.spindles is not None and args.stations > 1:
        raise ConfigError(
            f"--spindles with --stations {args.stations}: a line of multi-spindle stations "
            "needs station files of its own (each spindle's tool id is its own)"
        )


def run(args: argparse.Namespace) -> int:
    from services.cli.station_run import StationRun
    from services.rig.selection import choose_program
    from services.rig.service import RUN_ID_MAX
    from shared.config import check_derivable, derive_stations, load_line, load_station
    from shared.errors import ConfigError

    _check_counts(args)
    first_run_id = int(time.time())  # what the rig numbers its first run with
    station = load_station(args.config)
    spindles = args.spindles or station.config.station.spindles
    if first_run_id + args.runs * spindles - 1 > RUN_ID_MAX:
        raise ConfigError(
            f"--runs must be at most {(RUN_ID_MAX - first_run_id + 1) // spindles} (got "
            f"{args.runs}): run ids count from the current Unix time and end at {RUN_ID_MAX}"
        )
    program = choose_program(station, args.program)
    if station.config.zenoh.mode != "client" or not station.config.zenoh.connect:
        raise ConfigError(
            f"{station.path}: zenoh: boltwatch up runs a router and needs mode = 'client' "
            "with connect = [its endpoint]"
        )
    if args.controller == "openprotocol" and args.stations > 1:
        raise ConfigError(
            f"--stations {args.stations}: --controller openprotocol runs one station "
            "(each station's controller needs its own [openprotocol] port)"
        )
    if args.stations > 1:
        check_derivable(args.config, args.stations)  # its numbers, before anything is written
    station.make_recordings_folder()  # its logs go there too: refused now, naming the key
    stamp = datetime.now(UTC).strftime("%Y%m%d-%H%M%S")
    log_dir = station.recordings_folder / "logs" / f"up-{stamp}"
    stations = (
        [station]
        if args.stations == 1
        else load_line(derive_stations(args.config, args.stations, log_dir / "stations"))
    )
    base = args.config
    if args.controller == "openprotocol" and station.config.openprotocol is None:
        base = with_local_controller(args.config, log_dir / "stations")
        stations = [load_station(base)]
    if args.spindles is not None and args.spindles != station.config.station.spindles:
        stations = [load_station(with_spindles(base, log_dir / "spindles", args.spindles))]

    def on_signal(signum: int, _frame: FrameType | None) -> None:
        raise StoppedBySignalError(signal.Signals(signum).name)

    station_run = StationRun(
        stations, program, args.runs, log_dir, args.startup_timeout_s, controller=args.controller
    )
    previous = {s: signal.signal(s, on_signal) for s in (signal.SIGTERM, signal.SIGHUP)}
    try:
        return station_run.run()
    except (KeyboardInterrupt, StoppedBySignalError):
        print("\ninterrupted: stopping every process", file=sys.stderr)
        station_run.stop_everything()
        station_run.report()
        return 130
    finally:
        station_run.stop_everything()
        for sig, handler in previous.items():
            signal.signal(sig, handler)
