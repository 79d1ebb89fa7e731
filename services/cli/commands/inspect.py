"""``boltwatch inspect RUN.mcap [--out RUN.png]``: a picture of a recorded run;
``boltwatch inspect RUN.mcap --rerun [--out RUN.rrd]``: its Rerun recording, made from
the MCAP (:mod:`shared.recordings.rerun.rrd_from_mcap`);
``boltwatch inspect --overlay RUN... [--reference RUN] [--align POINT]``: several runs
on one figure (:mod:`services.cli.run_overlay`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from services.cli.command_options import (
    add_run_option,
    add_station_file_option,
    check_png_target,
    warn_damaged_recording,
)
from shared.errors import InputError

NAME = "inspect"
HELP = (
    "draw a recorded run as a post-mortem PNG of the paper's figures (10, 13-15, 22, 23), "
    "or several runs overlaid (--overlay)"
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Draw one run of an MCAP recording into a one-page PNG report after the paper's "
        "figures: torque and preload with detected peaks, plateaus and the stop decision "
        "(Fig. 10); f_ss, force step, torque drop and K1-K3 per event (Figs. 13-15); the "
        "errors of the 1st-3rd predictions (Figs. 22, 23, eqs. 61-63). With the joint and "
        "program metadata in the file, the analytical bounds are drawn too. For interactive "
        "viewing open the .mcap in Foxglove (it needs no plug-in). With --overlay: several "
        "runs' torque and preload over angle and over time on one figure, aligned at one "
        "point, with their programs' windows and each run's OK/NOK. With --rerun: the run's "
        "Rerun recording (.rrd), made from the MCAP, for a recorder that writes MCAP only "
        "(serve recorder --no-rerun, as a line of many stations does)."
    )
    parser.add_argument(
        "recording", type=Path, nargs="?", default=None, metavar="RUN.mcap", help="the recording"
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=None,
        metavar="FILE.png",
        help="default: beside the recording (--overlay: overlay.png in the current folder)",
    )
    parser.add_argument(
        "--rerun",
        action="store_true",
        help="write the run's Rerun recording (RUN.rrd beside the recording, or --out "
        "FILE.rrd) instead of the picture; open it with: rerun RUN.rrd boltwatch.rbl",
    )
    add_run_option(
        parser,
        "run id to draw (default: the run with the most samples; the output names the others)",
    )
    overlay = parser.add_argument_group("overlay (several runs on one figure)")
    overlay.add_argument(
        "--overlay",
        nargs="+",
        default=None,
        metavar="RUN",
        help="runs to draw: run ids (found in the station's recordings, see --config) or "
        "MCAP paths",
    )
    overlay.add_argument(
        "--cycle",
        action="store_true",
        help="each RUN stands for its whole multi-spindle cycle: every spindle's run of it, "
        "overlaid in spindle order",
    )
    overlay.add_argument(
        "--reference", default=None, metavar="RUN", help="a run drawn distinct (black, on top); "
        "the others are aligned onto it"
    )  # fmt: skip
    overlay.add_argument(
        "--align",
        default="start",
        metavar="start|torque:NM|first-slip",
        help="where runs are aligned: the start of the run, where torque first reaches NM, "
        "or the first stick-slip event (default: start)",
    )
    add_station_file_option(overlay, "station file, whose recordings the run ids are found in")


def run(args: argparse.Namespace) -> int:
    if args.overlay is not None:
        if args.recording is not None or args.run is not None:
            raise InputError(
                "--overlay takes its runs after it (run ids or MCAP paths); "
                "give no RUN.mcap or --run with it"
            )
        from services.cli.run_overlay import run_overlay

        return run_overlay(args)
    if args.recording is None:
        raise InputError("give a recording (RUN.mcap) to draw, or --overlay RUN...")
    if args.rerun:
        return _write_rrd(args)
    if args.reference is not None or args.align != "start" or args.cycle:
        option = "--reference" if args.reference is not None else "--align"
        option = "--cycle" if args.cycle else option
        raise InputError(f"{option} is an option of --overlay; give --overlay RUN... with it")
    from shared.offline.post_mortem import draw_run

    target = args.out or args.recording.with_suffix(".png")
    check_png_target(target, "the report")
    run = draw_run(args.recording, target, args.run)
    if not run.complete:
        warn_damaged_recording(NAME, run.state, "drew what is readable")
    others = [other for other in run.runs_in_file if other != run.run_id]
    also = f" (other runs in the file: {', '.join(map(str, others))})" if others else ""
    print(
        f"wrote {target}: run {run.run_id}, {len(run.samples)} samples, "
        f"{len(run.events)} stick-slip events{also}"
    )
    return 0


def _write_rrd(args: argparse.Namespace) -> int:
    from shared.recordings import rerun_path

    if args.run is not None or args.overlay is not None:
        raise InputError("--rerun writes the whole file's run; give no --run or --overlay with it")
    target = args.out or rerun_path(args.recording)
    if target.suffix.lower() != ".rrd":
        raise InputError(
            f"{target}: a Rerun recording is written as .rrd; give a path ending in .rrd"
        )
    if target.exists():
        raise InputError(f"{target} exists (the recorder wrote it live?); give another --out")
    from shared.recordings.rerun import BLUEPRINT_FILE, rrd_from_mcap

    written = rrd_from_mcap(args.recording, target)
    if not written.scan.complete:
        warn_damaged_recording(NAME, written.scan.describe(), "converted what is readable")
    print(
        f"wrote {target}: run {written.run_id} of {written.station}, {written.samples} samples, "
        f"{written.events} stick-slip events; open it: rerun {target} "
        f"{target.parent / BLUEPRINT_FILE}"
    )
    return 0
