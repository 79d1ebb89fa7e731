"""The acquisition loop: CAN frames in, samples and run states out (transport-agnostic).

:class:`Acquisition` owns the bus reading and the fault counters; where its
output goes is an :class:`Outlet` (zenoh in the service, a list in tests).
With a :class:`~services.acquisition.decider.Decider` (the station's edge
predictor) every complete sample is decided on right here, on the CAN
thread, before it is published: a decision goes out as a ``StopCommand``
within the same call (the stop path of one sample). ``send_stop`` may also be
called from another thread (the zenoh decision callback: a predictor
elsewhere on the line) and turns a decision for the running run into one CAN
``StopCommand``.

Each sample carries its time on the tool's own clock (``Sample.time_s``:
its unrolled Counter at the contract's sample rate), which the predictor
decides on: the receive time (``time_ns``) jitters with the host's
scheduling, the Counter does not.

``decision`` (a payload) and ``send_stop`` (a decoded decision) may be
called from another thread (the zenoh decision callback) and turn a decision
for the running run into one CAN ``StopCommand``. A payload that is not a
valid :class:`StopDecision` of this station (bad JSON, an unknown reason, an
advisory decision (decided after the fact, never acted on), a
string run id, a time no clock can hold, a run id wider than the DBC's
``RunId``, another station's id) is counted
in ``BusStats.bad_decisions`` and logged once, then at most every 10 s; a
good decision after it still stops the tool.
"""

from __future__ import annotations

import logging
import time
from collections import Counter, deque
from collections.abc import Callable
from typing import Protocol

import can

from services.acquisition.decider import Decider
from services.acquisition.frame_decoder import (
    FrameDecoder,
    JointSensorsFrame,
    Rejected,
    StageCommandFrame,
    StopCommandFrame,
    ToolSensorsFrame,
    ToolStageFrame,
    ToolStatusFrame,
)
from services.acquisition.pairing import AssembledSample, SampleAssembler
from services.acquisition.tool_commands import ToolCommands
from shared.contract import (
    SAMPLE_RATE_HZ,
    BusStats,
    Sample,
    StageDecision,
    StationDatabase,
    StopDecision,
    ToolRunState,
    ToolStageCode,
    ToolStageName,
    ToolState,
    can_id_bounds,
    codec,
)
from shared.errors import InputError
from shared.runtime import RateLimitedLog

LOG = logging.getLogger(__name__)

RECEIVE_ERROR_BACKOFF_S = 0.05
#: run ids remembered as started: a ToolStatus starting one of them again is ignored
STARTED_RUNS_KEPT = 64


class Outlet(Protocol):
    """Where the acquisition's output goes."""

    def sample(self, sample: Sample) -> None: ...
    def tool_state(self, state: ToolState) -> None: ...
    def bus_stats(self, stats: BusStats) -> None: ...


class Acquisition:
    """Reads one station's CAN bus; pairs, stamps and forwards samples."""

    def __init__(
        self,
        station_id: str,
        has_force_sensor: bool,
        bus: can.BusABC,
        database: StationDatabase,
        outlet: Outlet,
        clock_ns: Callable[[], int] = time.time_ns,
        unsent_samples: Callable[[], int] = lambda: 0,
        decider: Decider | None = None,
        stage_commands: bool = True,
    ) -> None:
        """``unsent_samples``: how many samples the outlet could not deliver (no router);
        ``decider``: decides on each sample on this thread (the edge predictor), or None;
        ``stage_commands``: the station file lets it command a final stage (when the DBC
        and the tool controller do too: :mod:`.tool_commands`)."""
        self._decider = decider
        self.station_id = station_id
        self._unsent_samples = unsent_samples
        self._bus = bus
        self._database = database
        self._decoder = FrameDecoder(database)
        self._outlet = outlet
        self._clock_ns = clock_ns
        self._started_ns = clock_ns()
        self._assembler = SampleAssembler(has_force_sensor)
        self._rejected: Counter[str] = Counter()
        self._frames = 0
        self._receive_errors = 0
        self._bad_decisions = 0
        run_bounds = {"run_id": can_id_bounds(database)["run_id"]}
        self._decode_decision = codec.decoder(StopDecision, run_bounds)
        self._decode_stage = codec.decoder(StageDecision, run_bounds)
        self._commands = ToolCommands(database, bus, stage_commands, clock_ns)
        self._run_commands = self._commands.mode
        self._stage: tuple[ToolStageName, int] | None = None  # the running run's (stage, pulses)
        self._log_bad_decision = RateLimitedLog(LOG, logging.ERROR)
        self._log_late_decision = RateLimitedLog(LOG, logging.WARNING)
        self._tool: ToolStatusFrame | None = None
        self._started_runs: deque[int] = deque(maxlen=STARTED_RUNS_KEPT)
        self._repeated_runs = 0
        self._decider_errors = 0

    # -- receiving ---------------------------------------------------------------------

    def poll(self, timeout_s: float) -> None:
        """Receive and handle at most one frame, waiting up to ``timeout_s``."""
        try:
            message = self._bus.recv(timeout_s)
        except can.CanError as err:
            self._receive_errors += 1
            if self._receive_errors in (1, 10, 100) or self._receive_errors % 1000 == 0:
                LOG.warning("CAN receive error #%d: %s", self._receive_errors, err)
            time.sleep(RECEIVE_ERROR_BACKOFF_S)
            return
        if message is not None:
            self.handle(message)

    def handle(self, message: can.Message) -> None:
        """Handle one received frame; bad frames are counted, never raised."""
        self._frames += 1
        bus_timed = bool(message.timestamp)  # the driver's (kernel's) receive time
        time_ns = round(message.timestamp * 1e9) if bus_timed else self._clock_ns()
        frame = self._decoder.decode(
            message.arbitration_id,
            message.data,
            is_error_frame=message.is_error_frame,
            is_remote_frame=message.is_remote_frame,
        )
        if isinstance(frame, ToolSensorsFrame):
            self._emit(
                self._assembler.tool_frame(
                    frame.counter, frame.torque_nm, frame.angle_deg, time_ns, bus_timed
                )
            )
        elif isinstance(frame, JointSensorsFrame):
            self._emit(self._assembler.joint_frame(frame.counter, frame.force_n, time_ns))
        elif isinstance(frame, ToolStatusFrame):
            self._tool_status(frame, time_ns)
        elif isinstance(frame, ToolStageFrame):
            self._tool_stage(frame, time_ns)
        elif isinstance(frame, Rejected):
            self._rejected[frame.reason] += 1
            if LOG.isEnabledFor(logging.DEBUG):
                LOG.debug("rejected frame 0x%x: %s", message.arbitration_id, frame.reason)
        elif isinstance(frame, StopCommandFrame | StageCommandFrame):
            LOG.debug("%s from another node for run %d", type(frame).__name__, frame.run_id)

    def _emit(self, samples: list[AssembledSample]) -> None:
        run_id = self._tool.run_id if self._tool is not None else 0
        decider = self._decider
        for assembled in samples:
            sample = Sample(
                self.station_id,
                run_id,
                assembled.sequence,
                assembled.time_ns,
                assembled.torque_nm,
                assembled.angle_deg,
                assembled.force_n,
                assembled.sequence / SAMPLE_RATE_HZ,
            )
            if decider is not None:
                try:
                    decision = decider.on_sample(sample)
                except Exception:  # a fault in the predictor: its tool's own shutoff holds
                    self._decider_failed()
                else:
                    if decision is not None:
                        self.send(decision)  # before anything else: the stop path
            self._outlet.sample(sample)

    def _tool_status(self, frame: ToolStatusFrame, time_ns: int) -> None:
        try:
            state_name = ToolRunState(frame.state).name.lower()
        except ValueError:
            self._rejected["bad_state"] += 1  # never let a corrupt state restart the run
            return
        previous = self._tool
        if previous == frame:
            return
        starts_run = frame.state == ToolRunState.RUNNING and (
            previous is None
            or previous.run_id != frame.run_id
            or previous.state != ToolRunState.RUNNING
        )
        if starts_run and frame.run_id in self._started_runs:
            # a run id starts once, however its state flips: one run, one summary, one file
            self._repeated_runs += 1
            if self._repeated_runs in (1, 10, 100) or self._repeated_runs % 1000 == 0:
                LOG.warning(
                    "run %d started again (ToolStatus flipping?): ignored (#%d)",
                    frame.run_id,
                    self._repeated_runs,
                )
            return
        if previous is not None and (starts_run or frame.state != ToolRunState.RUNNING):
            self._emit(self._assembler.finish_run())  # leftovers belong to the old run
        if starts_run:
            self._started_runs.append(frame.run_id)
            self._assembler.start_run()
            self._run_commands = self._commands.run_commands()
            # a staged tool starts each run in its rundown (its ToolStage said so before)
            self._stage = ("rundown", 0) if self._run_commands == "staged" else None
        self._tool = frame
        ended = frame.state in (ToolRunState.DONE, ToolRunState.ABORTED)
        commands = self._commands
        stage, pulses = self._stage if self._stage is not None else (None, 0)
        state = ToolState(
            self.station_id,
            frame.run_id,
            frame.tool_id,
            frame.program_id,
            state_name,  # type: ignore[arg-type]
            time_ns,
            stop_command=(
                commands.stopped_reason if ended and commands.stopped_run == frame.run_id else None
            ),
            commands=self._run_commands,
            stage=stage if frame.state == ToolRunState.RUNNING else None,
            pulses=pulses,
        )
        self._tell(state)
        LOG.info("run %d: %s (program %d)", frame.run_id, state_name, frame.program_id)

    def _tool_stage(self, frame: ToolStageFrame, time_ns: int) -> None:
        """A staged tool's ToolStage: its features; a new stage of the running run is a new
        ToolState (running, with the stage), told to the predictor and the line."""
        self._commands.heard(frame)
        tool = self._tool
        if tool is None or tool.state != ToolRunState.RUNNING or frame.run_id != tool.run_id:
            return  # a run's features come before its start; stale ones are no news
        try:
            stage_name: ToolStageName = ToolStageCode(frame.stage).name.lower()  # type: ignore[assignment]
        except ValueError:
            self._rejected["bad_state"] += 1
            return
        if (stage_name, frame.pulses) == self._stage:
            return
        self._stage = (stage_name, frame.pulses)
        self._tell(
            ToolState(
                self.station_id,
                tool.run_id,
                tool.tool_id,
                tool.program_id,
                "running",
                time_ns,
                commands=self._run_commands,
                stage=stage_name,
                pulses=frame.pulses,
            )
        )
        LOG.info("run %d: %s (pulses %d)", tool.run_id, stage_name, frame.pulses)

    def _tell(self, state: ToolState) -> None:
        """A run state to the station's predictor (edge) and to the line."""
        if self._decider is not None:
            try:
                self._decider.on_tool_state(state)
            except Exception:
                self._decider_failed()
        self._outlet.tool_state(state)

    def _decider_failed(self) -> None:
        """The predictor raised: logged (rate-limited), counted; samples still flow."""
        self._decider_errors += 1
        if self._decider_errors in (1, 10, 100) or self._decider_errors % 1000 == 0:
            LOG.exception(
                "the station's predictor failed (#%d); the tool's own shutoff stops this run",
                self._decider_errors,
            )

    # -- stopping ------------------------------------------------------------------------

    def decision(self, payload: bytes, key: str = "decision") -> bool:
        """A decision payload received on ``key``: a StopCommand if it is a valid decision for
        the running run (see :meth:`send`); a bad payload is counted, never raised."""
        try:
            decision = self._decode_decision(payload)
            if decision.advisory:  # decided after the fact (import, a controller's bridge)
                raise InputError("an advisory decision (decided after the fact) stops no tool")
        except InputError as err:
            return self._bad_decision(key, err)
        return self.send(decision, key)

    def stage(self, payload: bytes, key: str = "stage") -> bool:
        """A final stage's command received on ``key`` (a line predictor's): a StageCommand
        or a pulse's StopCommand for the running run; a bad payload is counted."""
        try:
            decision = self._decode_stage(payload)
        except InputError as err:
            return self._bad_decision(key, err)
        return self.send(decision, key)

    def _bad_decision(self, key: str, err: InputError) -> bool:
        self._bad_decisions += 1
        self._log_bad_decision(
            "bad decision payload on %s ignored (#%d): %s", key, self._bad_decisions, err
        )
        return False

    def send(self, decision: StopDecision | StageDecision, key: str = "") -> bool:
        """The CAN command for ``decision`` if it is for the running run: the run's first
        halt once (StopCommand), a staged tool's commands (:mod:`.tool_commands`)."""
        if decision.station != self.station_id:
            error = InputError(f"a decision of station {decision.station!r}, not of this one")
            return self._bad_decision(key or "the station's predictor", error)
        if isinstance(decision, StopDecision):
            return self._commands.stop(decision, self._tool)
        return self._commands.stage(decision, self._tool)

    def send_stop(self, decision: StopDecision) -> bool:
        """Send StopCommand for ``decision`` if it is for the running run; once per run."""
        return self.send(decision)

    # -- counters ------------------------------------------------------------------------

    def stats(self) -> BusStats:
        pairing = self._assembler.counters
        commands = self._commands
        rejected = self._rejected
        return BusStats(
            station=self.station_id,
            time_ns=self._clock_ns(),
            frames=self._frames,
            samples=pairing.samples,
            unknown_ids=rejected["unknown_id"] + rejected["remote_frame"],
            wrong_length=rejected["wrong_length"],
            decode_errors=rejected["decode_error"] + rejected["bad_state"],
            error_frames=rejected["error_frame"],
            receive_errors=self._receive_errors,
            counter_gaps=pairing.counter_gaps,
            missed_samples=pairing.missed_samples,
            counter_faults=pairing.repeated + pairing.backwards + pairing.implausible,
            unpaired=pairing.unpaired,
            orphans=pairing.orphans,
            stop_commands=commands.stop_commands,
            unsent_samples=self._unsent_samples(),
            late_decisions=commands.late_decisions,
            bad_decisions=self._bad_decisions,
            started_ns=self._started_ns,
            repeated_runs=self._repeated_runs,
            tool_commands=commands.mode,
            tool_commands_note=commands.note,
            stage_commands=commands.stage_commands,
            refused_stages=commands.refused_stages,
        )
