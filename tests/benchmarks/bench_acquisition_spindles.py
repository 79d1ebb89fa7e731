"""The acquisition's CAN-thread work per sample for a multi-spindle station (not a test).

Run on demand::

    .venv/bin/python tests/benchmarks/bench_acquisition_spindles.py [--spindles 1 4 10] [--cycles 2]

The simulated rig's N spindles (program 2 of the shipped station) tighten
``--cycles`` cycles on a python-can ``virtual`` bus; every frame is kept,
then handed to the acquisition (its lanes, the frame decoder, the pairing)
with the station's predictor deciding on each sample (its run bookkeeping and
core, as at the edge), in this process: the CPU time of that loop over the
samples it made is the work the stop path does per sample on the CAN thread,
without the rig, the publisher thread, zenoh or the recorder beside it (what
``bench_stop_path.py --spindles N`` measures with everything running).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import threading
import time
import uuid
from pathlib import Path

import can

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from services.acquisition.acquisition import Acquisition
from services.rig.frames import RigFrames
from services.rig.multi_spindle import MultiSpindleRig
from services.rig.realtime import RealtimeRig, ToolIdentity
from shared.config import load_station
from shared.contract import StationDatabase
from shared.model import JointConstants
from tests.support.acquisition_bus import ListOutlet, StationPredictor
from tests.support.station_files import write_station


def frames_of(spindles: int, cycles: int, folder: Path) -> tuple[list[can.Message], Path]:
    """Every frame the rig's ``spindles`` put on the bus in ``cycles`` cycles."""
    replacements = {"pause_between_runs_s = 0.3": "pause_between_runs_s = 0.0"}
    if spindles > 1:
        replacements["has_force_sensor = true"] = f"has_force_sensor = true\nspindles = {spindles}"
    path = write_station(folder, replacements=replacements)
    station = load_station(path)
    config = station.config
    database = StationDatabase(station.dbc_path)
    channel = f"bench-{uuid.uuid4().hex}"
    frames: list[can.Message] = []
    with (
        can.Bus(interface="virtual", channel=channel) as tool,
        can.Bus(interface="virtual", channel=channel) as listen,
    ):
        arguments = (
            tool,
            RigFrames(database),
            JointConstants.of(station.joint),
            config.rig,
            ToolIdentity(config.station.tool_id, True),
        )
        rig: RealtimeRig
        if spindles > 1:
            tools = [config.station.tool_of(k) for k in range(1, spindles + 1)]
            rig = MultiSpindleRig(*arguments, tool_ids=tools, id_stride=2)
        else:
            rig = RealtimeRig(*arguments)
        stop = threading.Event()
        worker = threading.Thread(
            target=lambda: rig.run_many(config.program(2), 1000, 3, stop, runs=cycles)
        )
        worker.start()
        while True:
            message = listen.recv(0.05)
            if message is not None:
                frames.append(message)
            elif not worker.is_alive():
                break
        worker.join()
    return frames, path


def cost_per_sample_us(spindles: int, frames: list[can.Message], path: Path) -> tuple[int, float]:
    station = load_station(path)
    database = StationDatabase(station.dbc_path)
    predictor, outlet = StationPredictor(station), ListOutlet()
    with can.Bus(interface="virtual", channel=f"idle-{uuid.uuid4().hex}") as bus:
        acquisition = Acquisition(
            "st1", True, bus, database, outlet, decider=predictor, spindles=spindles
        )
        started = time.process_time()
        for message in frames:
            acquisition.handle(message)
        used_s = time.process_time() - started
    return len(outlet.samples), 1e6 * used_s / max(1, len(outlet.samples))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--spindles", type=int, nargs="+", default=[1, 4, 10])
    parser.add_argument("--cycles", type=int, default=2)
    args = parser.parse_args()
    for spindles in args.spindles:
        with tempfile.TemporaryDirectory(prefix="bench-acquisition-spindles-") as folder:
            frames, path = frames_of(spindles, args.cycles, Path(folder))
            samples, cost_us = cost_per_sample_us(spindles, frames, path)
        print(
            f"{spindles:>3} spindle(s): {len(frames)} frames, {samples} samples, "
            f"{cost_us:.1f} µs of CPU a sample on the CAN thread (decode, pair, decide): "
            f"{cost_us * spindles / 10:.1f} % of a core at 1 kHz"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
