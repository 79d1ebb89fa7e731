"""One spindle of a station as the acquisition follows it: its run, its Counter, its commands.

A station of one spindle has one lane; a multi-spindle system (N spindles
tightening one part in one synchronised cycle, each with its own frames on
the bus: :class:`~shared.contract.SpindleIds`) has one per spindle, each
pairing its own two sensor frames by its own ``Counter``, following its own
run, and sending its own ``StopCommand`` at its own id. What the lanes share
(the station's counters of bad frames, the last ``CycleStart``) stays in
:class:`~services.acquisition.acquisition.Acquisition`.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable

import can

from services.acquisition.frame_decoder import ToolStatusFrame
from services.acquisition.pairing import SampleAssembler
from services.acquisition.tool_commands import ToolCommands
from shared.contract import StationDatabase, ToolCommandsName, ToolStageName

#: run ids remembered as started: a ToolStatus starting one of them again is ignored
STARTED_RUNS_KEPT = 64


class SpindleLane:
    """The run, sample pairing and commands of one spindle."""

    def __init__(
        self,
        spindle: int,
        has_force_sensor: bool,
        database: StationDatabase,
        bus: can.BusABC,
        stage_commands: bool,
        clock_ns: Callable[[], int],
        id_offset: int = 0,
    ) -> None:
        self.spindle = spindle
        self.assembler = SampleAssembler(has_force_sensor)
        self.commands = ToolCommands(database, bus, stage_commands, clock_ns, id_offset)
        self.run_commands: ToolCommandsName = self.commands.mode
        self.stage: tuple[ToolStageName, int] | None = None  # the running run's (stage, pulses)
        self.tool: ToolStatusFrame | None = None  # the last ToolStatus heard
        self.started_runs: deque[int] = deque(maxlen=STARTED_RUNS_KEPT)
        self.sync_id: int | None = None  # the cycle of the run started last (multi-spindle)

    @property
    def run_id(self) -> int:
        """The run the spindle's samples are of (0: none heard yet)."""
        return self.tool.run_id if self.tool is not None else 0
