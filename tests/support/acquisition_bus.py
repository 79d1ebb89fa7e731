"""The acquisition on a python-can virtual bus, for tests: frames of the station's DBC, an
outlet that keeps what the acquisition publishes, and the station's predictor as the edge
runs it, without its zenoh side."""

from __future__ import annotations

import time

import can

from services.acquisition.acquisition import Acquisition
from services.predictor.served_station import ServedStation
from services.predictor.station_runs import StationRuns
from shared.config import LoadedStation
from shared.contract import (
    BusStats,
    Sample,
    StageDecision,
    StationDatabase,
    StopDecision,
    ToolState,
)
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


class StationPredictor:
    """The station's predictor as the edge runs it (StationRuns), without its zenoh side: what
    it would publish is kept here."""

    def __init__(self, station: LoadedStation) -> None:
        self.runs = StationRuns(ServedStation(station))
        self.published: list[object] = []

    def on_tool_state(self, state: ToolState) -> None:
        self.published += self.runs.on_tool(state)

    def on_sample(self, sample: Sample) -> StopDecision | StageDecision | None:
        decision = None
        for message in self.runs.on_sample(sample, time.time_ns()):
            self.published.append(message)
            if isinstance(message, StopDecision | StageDecision):
                decision = message
        return decision

    def of(self, kind: type) -> list:
        return [m for m in self.published if isinstance(m, kind)]
