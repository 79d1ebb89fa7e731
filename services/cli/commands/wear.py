"""``boltwatch wear``: the wear ledger (how much vibration each tool has taken).

::

    boltwatch wear [--recordings DIR] [--station ST]      the table, one line per tool,
                   [--threshold I] [--json]               then each tool's service forecast
    boltwatch wear service TOOL --note TEXT               record a service of TOOL
    boltwatch wear reset [--recordings DIR]               a broken ledger moved aside, a new one
    boltwatch wear --plant [--config FILE | --connect EP]  every line's ledger, over zenoh

Below the table, each tool's service forecast against the station file's
``recorder.wear_service_threshold`` (or ``--threshold``): when it is due, how
sure (80 %), the production days and tightenings left, the shift change to plan
the service at, and what wears it most (:mod:`shared.wear.wear_forecast_table`).
``--json``: each tool's line with its ``outlook``, ``forecast`` and ``wear_by``
(the share of its wear since its service by program, station and joint).

``--plant`` asks every recorder of the plant (``boltwatch/*/wear`` through the
router of the station file, or ``--connect``; the routers of a plant's lines
are meshed) and merges their replies (:mod:`shared.wear.wear_plant`). A
recorder that replies with an error is named on stderr, what the others said
is printed, and the exit status is 2.

A broken ledger (empty, not SQLite, another schema, corrupt) is one line
naming the file, what is wrong and the reset command, exit status 2.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from services.cli.command_options import add_recordings_folder_options, recordings_folder
from shared.option_types import float_in, int_in, seconds

if TYPE_CHECKING:
    from shared.wear import ToolWear

NAME = "wear"
HELP = "show the wear ledger per tool, record a tool's service, or replace a broken ledger"

#: the largest tool id (station.tool_id in a station file; 16 bits on CAN)
MAX_TOOL_ID = 65535


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Show the accumulated stick-slip intensity per tool (I_total = Σ I_process, eq. 69), "
        "its runs, intensity per run, worst runs and the intensity since the last service. "
        "'boltwatch wear service TOOL --note TEXT' records a service: the interval count "
        "restarts, the history stays. Tools are plant assets: a tool's totals count its "
        "runs at every station; --station ST lists the tools that ran at ST. "
        "'boltwatch wear reset' moves a broken ledger (empty, not SQLite, another schema, "
        "corrupt) aside, keeping it as wear.sqlite.broken-<UTC time>, and starts a new one; "
        "a running recorder then counts the runs it kept waiting into the new ledger. "
        "It refuses a healthy ledger and one a process has open. Below the table: each "
        "tool's service forecast (the date its intensity since service reaches the "
        "threshold, with an 80 %% interval, from its intensity per production day; the "
        "production days and shifts learned from the ledger's own runs), the tightenings "
        "left, and what wears it most."
    )
    parser.add_argument(
        "action",
        nargs="?",
        choices=["service", "reset"],
        help="service: record a service of TOOL; reset: replace a broken ledger",
    )
    parser.add_argument(
        "tool", nargs="?", type=int_in(0, MAX_TOOL_ID, "a tool id"), help="tool id (with 'service')"
    )
    parser.add_argument("--note", default="", help="what was done (with 'service')")
    add_recordings_folder_options(parser, "recordings folder holding wear.sqlite")
    parser.add_argument(
        "--station",
        default=None,
        metavar="ST",
        help="only the tools that ran at station ST (their totals still count every station)",
    )
    parser.add_argument(
        "--threshold",
        type=float_in(0.0, 1e300, "", low_allowed=False),
        default=None,
        metavar="I",
        help="the intensity since service a tool is due at, for the forecast (default: the "
        "station file's recorder.wear_service_threshold)",
    )
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    plant = parser.add_argument_group("the whole plant (every line's recorder, over zenoh)")
    plant.add_argument(
        "--plant",
        action="store_true",
        help="ask every line's recorder (boltwatch/*/wear) through the router of --config's "
        "station file, with its TLS files, and merge their ledgers",
    )
    plant.add_argument(
        "--connect",
        default=None,
        metavar="ENDPOINT",
        help="the router to ask, e.g. tcp/10.0.1.5:7447 (implies --plant; plain tcp)",
    )
    plant.add_argument(
        "--timeout-s",
        type=seconds,
        default=5.0,
        metavar="S",
        help="how long to wait for the recorders' replies (default 5)",
    )


def run(args: argparse.Namespace) -> int:
    import time

    from shared.errors import InputError
    from shared.wear import WearLedger, ledger_path

    if args.plant or args.connect is not None:
        return _plant(args)
    path = ledger_path(recordings_folder(args))
    if args.action == "reset":
        return _reset(args, path)
    threshold, joints = _station_file_says(args)
    if args.action == "service":
        if args.tool is None:
            raise InputError("give the tool id: boltwatch wear service TOOL --note TEXT")
        with WearLedger(path) as ledger:
            ledger.record_service(args.tool, args.note, time.time_ns())
            tools = [ledger.tool(args.tool, joints=joints)]
        print(f"recorded a service of tool {args.tool} in {path}")
    else:
        with WearLedger(path, read_only=True) as ledger:
            tools = ledger.tools(station=args.station, joints=joints)
    _print(args, tools, threshold)
    return 0


def _station_file_says(args: argparse.Namespace) -> tuple[float | None, dict[tuple[str, int], str]]:
    """The threshold (``--threshold``, else the station file's) and the joints of its
    programs; none from a station file that is not there or not readable when
    ``--recordings`` says where the ledger is."""
    from shared.config import load_any_station
    from shared.errors import ConfigError, InputError
    from shared.wear import joint_names

    try:
        station = load_any_station(args.config)
    except (ConfigError, InputError, OSError):
        if args.recordings is None:
            raise
        return args.threshold, {}
    threshold = args.threshold or station.config.recorder.wear_service_threshold
    return threshold, joint_names([station])


def _print(args: argparse.Namespace, tools: list[ToolWear], threshold: float | None) -> None:
    """The table and the forecasts (or their JSON) of ``tools``."""
    import json
    import time

    from shared.wear import format_table
    from shared.wear.wear_forecast_table import forecast_json, format_forecasts, tool_forecasts

    forecasts = tool_forecasts(tools, threshold, time.time_ns())
    if args.json:
        lines = [forecast_json(tool, told) for tool, told in zip(tools, forecasts, strict=True)]
        print(json.dumps(lines, indent=2))
        return
    print(format_table(tools, args.station))
    table = format_forecasts(tools, forecasts)
    if table:
        print()
        print(table)


def _reset(args: argparse.Namespace, path: Path) -> int:
    from shared.errors import InputError
    from shared.wear import reset_ledger

    if args.tool is not None:
        raise InputError("reset takes no tool id: boltwatch wear reset [--recordings DIR]")
    done = reset_ledger(path)
    if done is None:
        print(f"no wear ledger at {path}: nothing to reset (the recorder starts one)")
        return 0
    kept = ", ".join(str(name) for name in done.kept)
    print(
        f"moved the broken wear ledger {path} aside ({done.broken}); kept as {kept}; "
        f"started a new ledger at {done.ledger}: a running recorder counts the runs it "
        "kept waiting into it within seconds"
    )
    return 0


def _plant(args: argparse.Namespace) -> int:
    """The merged ledgers of every line's recorder; 2 when one replied with an error."""
    import sys

    from services.cli.router_client import open_client, router_client
    from shared.contract import keys
    from shared.errors import InputError
    from shared.wear import WearReply, merge, parse_reply

    if args.action is not None:
        raise InputError(
            f"wear {args.action} works on one ledger file (--recordings), not --plant: "
            "run it on the line server whose recorder keeps the tool's runs"
        )
    endpoint, config = router_client(args.config, args.connect)
    replies: list[WearReply] = []
    failed: list[str] = []
    with open_client(endpoint, config) as session:
        import zenoh

        for reply in session.get(
            keys.station_key("*", keys.WEAR),
            target=zenoh.QueryTarget.ALL,
            consolidation=zenoh.ConsolidationMode.NONE,
            timeout=args.timeout_s,
        ):
            if reply.ok is not None:
                where = str(reply.ok.key_expr)
                try:
                    replies.append(parse_reply(reply.ok.payload.to_bytes()))
                except InputError as err:
                    failed.append(f"{where}: {err}")
            elif reply.err is not None:
                reason = reply.err.payload.to_bytes().decode(errors="replace")
                failed.append(f"a recorder could not read its ledger: {reason}")
    if not replies and not failed:
        raise InputError(
            f"no recorder answered a wear query through {endpoint} within {args.timeout_s:g} s"
        )
    tools = merge(replies, args.station)
    threshold, _ = _station_file_says(args) if args.connect is None else (args.threshold, {})
    _print(args, tools, threshold)
    if not args.json:
        ledgers = sorted({reply.ledger for reply in replies})
        stations = sorted({reply.station for reply in replies})
        print(f"{len(ledgers)} ledgers answered for stations {', '.join(stations) or '-'}")
    for line in failed:
        print(f"boltwatch wear: {line}", file=sys.stderr)
    return 2 if failed else 0
