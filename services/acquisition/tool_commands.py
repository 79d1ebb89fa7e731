"""What the station sends its tool controller: a StopCommand, and a staged tool's StageCommand.

A tool that only stops takes one ``StopCommand`` per run. A tool controller
that runs a program's final stage (``docs/reference/can-and-trace.md``) also
takes ``StageCommand`` (the final or the rundown speed, a pulse from the
halt, the run's finish), and each pulse is halted by a ``StopCommand`` of its
own. It says so in ``ToolStage.Features``, which it sends before each run's
first ``ToolStatus`` running. What the station may send in a run is fixed
when the run starts (:meth:`ToolCommands.run_commands`): ``staged`` only when

- the DBC has the final stage's messages (``StageCommand``, ``ToolStage``),
- the station file allows them (``[can] tool_commands = "auto"``, the default),
- and the tool controller said it takes them (the last ``ToolStage`` heard);

otherwise ``stop``, and a StageDecision for the run is refused: the station
never sends what its tool does not understand. Why a station runs stop-only
is :attr:`ToolCommands.note` (``boltwatch status``).

Sends run on the CAN thread (the edge predictor's decisions) or on zenoh's
(a line predictor's), under one lock; a decision for a run the tool is not
running, or a halt already sent, is counted and dropped.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

import can

from services.acquisition.frame_decoder import ToolStageFrame, ToolStatusFrame
from shared.contract import (
    FEATURE_STAGES,
    StageCommandCode,
    StageDecision,
    StageReason,
    StationDatabase,
    StopDecision,
    StopReason,
    StopReasonName,
    ToolCommandsName,
    ToolRunState,
)
from shared.runtime import RateLimitedLog

LOG = logging.getLogger(__name__)


class ToolCommands:
    """The station's commands to its tool, one run at a time."""

    def __init__(
        self,
        database: StationDatabase,
        bus: can.BusABC,
        allowed: bool,
        clock_ns: Callable[[], int],
        id_offset: int = 0,
    ) -> None:
        """``allowed``: the station file lets the station command a final stage;
        ``id_offset``: what this spindle's ids add to the DBC's (a multi-spindle station's
        spindle: :class:`~shared.contract.SpindleIds`)."""
        self._database = database
        self._id_offset = id_offset
        self._bus = bus
        self._allowed = allowed
        self._clock_ns = clock_ns
        self._lock = threading.Lock()
        self._features: int | None = None  # the last ToolStage's Features (None: none heard)
        self._run_commands: ToolCommandsName = "stop"
        self._halted: set[tuple[int, int]] = set()  # (run, pulse) a StopCommand went out for
        self.stopped_run: int | None = None  # the run of the first StopCommand sent
        self.stopped_reason: StopReasonName | None = None
        self.stop_commands = 0
        self.stage_commands = 0
        self.late_decisions = 0
        self.refused_stages = 0  # StageDecisions for a run whose tool takes none
        self._log_late = RateLimitedLog(LOG, logging.WARNING)
        self._log_refused = RateLimitedLog(LOG, logging.WARNING)

    # -- what the tool says ----------------------------------------------------------------

    def heard(self, frame: ToolStageFrame) -> None:
        """A ToolStage frame: the controller's features (before each run, and with it)."""
        self._features = frame.features

    def run_commands(self) -> ToolCommandsName:
        """What the station may send in the run that starts now (fixed for the run)."""
        self._run_commands = "staged" if not self.note else "stop"
        return self._run_commands

    @property
    def note(self) -> str:
        """Why the station commands stop only ("" when it may command a final stage)."""
        if not self._database.has_stages:
            return f"{self._database.path.name} has no StageCommand"
        if not self._allowed:
            return "the station file says can.tool_commands = 'stop'"
        if self._features is None:
            return "the tool controller sends no ToolStage"
        if not self._features & FEATURE_STAGES:
            return "the tool controller says it takes no StageCommand"
        return ""

    @property
    def mode(self) -> ToolCommandsName:
        """What the station would command in a run starting now."""
        return "stop" if self.note else "staged"

    # -- sending ------------------------------------------------------------------------------

    def stop(self, decision: StopDecision, tool: ToolStatusFrame | None) -> bool:
        """A StopCommand for the run's first halt, if the tool is running that run; once."""
        if not self._running(decision.run_id, tool):
            return False
        with self._lock:
            if self.stopped_run == decision.run_id:
                return False
            reason = StopReason[decision.reason.upper()]
            if not self._send_stop(decision.run_id, int(reason)):
                return False
            self.stopped_run = decision.run_id
            self.stopped_reason = decision.reason
            self._halted = {(decision.run_id, 0)}
        self._log_sent(decision.run_id, f"StopCommand ({decision.reason})", decision.time_ns)
        return True

    def stage(self, decision: StageDecision, tool: ToolStatusFrame | None) -> bool:
        """A final stage's command: a StageCommand, or the StopCommand that halts a pulse."""
        if not self._running(decision.run_id, tool):
            return False
        if self._run_commands != "staged":
            self.refused_stages += 1
            self._log_refused(
                "run %d: %s not sent: the tool runs stop only in this run (#%d)",
                decision.run_id,
                decision.command,
                self.refused_stages,
            )
            return False
        with self._lock:
            if decision.command == "stop":
                halt = (decision.run_id, decision.pulse)
                if halt in self._halted:
                    return False
                if not self._send_stop(decision.run_id, int(StopReason.TARGET_REACHED)):
                    return False
                self._halted.add(halt)
                what = f"StopCommand of pulse {decision.pulse}"
            else:
                if not self._send_stage(decision):
                    return False
                self.stage_commands += 1
                what = f"StageCommand {decision.command} ({decision.reason})"
        self._log_sent(decision.run_id, what, decision.time_ns)
        return True

    def _running(self, run_id: int, tool: ToolStatusFrame | None) -> bool:
        if tool is None or tool.state != ToolRunState.RUNNING or run_id != tool.run_id:
            self.late_decisions += 1
            self._log_late(
                "decision for run %d ignored: the tool is not running it (#%d)",
                run_id,
                self.late_decisions,
            )
            return False
        return True

    def _send_stop(self, run_id: int, reason: int) -> bool:
        data = self._database.encode("StopCommand", {"RunId": run_id, "Reason": reason})
        frame_id = self._database.stop_command_id + self._id_offset
        if not self._send("StopCommand", frame_id, data, run_id):
            return False
        self.stop_commands += 1
        return True

    def _send_stage(self, decision: StageDecision) -> bool:
        frame_id = self._database.stage_command_id
        assert frame_id is not None  # a staged run needs the DBC's StageCommand
        signals: dict[str, float | int] = {
            "RunId": decision.run_id,
            "Command": int(StageCommandCode[decision.command.upper()]),
            "Pulse": decision.pulse if decision.command == "pulse" else 0,
            "Reason": int(StageReason[decision.reason.upper()])
            if decision.reason.upper() in StageReason.__members__
            else int(StageReason.UNSPECIFIED),
        }
        data = self._database.encode("StageCommand", signals)
        return self._send("StageCommand", frame_id + self._id_offset, data, decision.run_id)

    def _send(self, name: str, frame_id: int, data: bytes, run_id: int) -> bool:
        message = can.Message(
            arbitration_id=frame_id, data=data, is_extended_id=self._database.is_extended(name)
        )
        try:
            self._bus.send(message)
        except can.CanError as err:
            LOG.error("%s for run %d could not be sent: %s", name, run_id, err)
            return False
        return True

    def _log_sent(self, run_id: int, what: str, decided_ns: int) -> None:
        lag_ms = (self._clock_ns() - decided_ns) / 1e6
        LOG.info("run %d: %s sent, %.2f ms after the deciding sample", run_id, what, lag_ms)
