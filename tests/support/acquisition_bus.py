"""The acquisition on a python-can virtual bus, for tests: frames of the station's DBC and
an outlet that keeps what the acquisition publishes."""

from __future__ import annotations

import can

from services.acquisition.acquisition import Acquisition
from shared.contract import BusStats, Sample, StationDatabase, ToolState
from tests.support.paths import DBC_FILE

DATABASE = StationDatabase(DBC_FILE)
FRAME_IDS = {name: frame_id for frame_id, (name, _) in DATABASE.by_id.items()}


class ListOutlet:
    """Collects what the acquisition publishes (implements the Outlet protocol)."""

    def __init__(self) -> None:
        self.samples: list[Sample] = []
        self.states: list[ToolState] = []
        self.stats: list[BusStats] = []

    def sample(self, sample: Sample) -> None:
        self.samples.append(sample)

    def tool_state(self, state: ToolState) -> None:
        self.states.append(state)

    def bus_stats(self, stats: BusStats) -> None:
        self.stats.append(stats)


def frame(name: str, **signals: float) -> can.Message:
    return can.Message(
        arbitration_id=FRAME_IDS[name],
        data=DATABASE.encode(name, signals),
        is_extended_id=False,
    )


def status(run_id: int, state: int) -> can.Message:
    return frame("ToolStatus", RunId=run_id, ToolId=7, ProgramId=1, State=state)


def drain(acquisition: Acquisition, bus: can.BusABC) -> None:
    """Poll until the bus has nothing more for us."""
    while True:
        message = bus.recv(0.05)
        if message is None:
            return
        acquisition.handle(message)
