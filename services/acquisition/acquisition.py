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

A multi-spindle station (``[station] spindles`` N > 1) has N spindles on its
bus, each at the DBC's ids shifted by its stride
(:class:`~shared.contract.SpindleIds`): each is a lane of its own
(:mod:`.spindle_lane`: its run, its Counter, its StopCommand), its samples
and states named by its run id as a single spindle's are; each run's
``ToolState`` says its spindle and the sync id of the cycle it started in (the
controller's last ``CycleStart``). A decision goes to the spindle running its
run. Counters are the station's, summed over its spindles.
"""

from __future__ import annotations

import logging
import time
from collections import Counter
from collections.abc import Callable
from typing import Protocol

import can

from services.acquisition.decider import Decider
from services.acquisition.frame_decoder import (
    CycleStartFrame,
    FrameDecoder,
    JointSensorsFrame,
    Rejected,
    StageCommandFrame,
    StopCommandFrame,
    ToolSensorsFrame,
    ToolStageFrame,
    ToolStatusFrame,
)
from services.acquisition.pairing import AssembledSample, PairingCounters
from services.acquisition.spindle_lane import SpindleLane
from shared.contract import (
    SAMPLE_RATE_HZ,
    BusStats,
    Sample,
    SpindleIds,
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
        spindles: int = 1,
        spindle_id_stride: int = 2,
    ) -> None:
        """``unsent_samples``: how many samples the outlet could not deliver (no router);
        ``decider``: decides on each sample on this thread (the edge predictor), or None;
        ``stage_commands``: the station file lets it command a final stage (when the DBC
        and the tool controller do too: :mod:`.tool_commands`); ``spindles``, its
        ``spindle_id_stride``: a multi-spindle station's (:class:`SpindleIds`)."""
        self._decider = decider
        self.station_id = station_id
        self._unsent_samples = unsent_samples
        self._bus = bus
        self._database = database
        spindle_ids = SpindleIds(database, spindles, spindle_id_stride)
        self._decoder = FrameDecoder(spindle_ids)
        self._outlet = outlet
        self._clock_ns = clock_ns
        self._started_ns = clock_ns()
        self._multi = spindles > 1
        self._lanes = {
            spindle: SpindleLane(
                spindle,
                has_force_sensor,
                database,
                bus,
                stage_commands,
                clock_ns,
                spindle_ids.offset(spindle),
            )
            for spindle in range(1, spindles + 1)
        }
        self._sync_id: int | None = None  # the last CycleStart's (a multi-spindle system)
        self._rejected: Counter[str] = Counter()
        self._frames = 0
        self._receive_errors = 0
        self._bad_decisions = 0
        run_bounds = {"run_id": can_id_bounds(database)["run_id"]}
        self._decode_decision = codec.decoder(StopDecision, run_bounds)
        self._decode_stage = codec.decoder(StageDecision, run_bounds)
        self._log_bad_decision = RateLimitedLog(LOG, logging.ERROR)
        self._log_late_decision = RateLimitedLog(LOG, logging.WARNING)
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
            lane = self._lanes[frame.spindle]
            self._emit(
                lane.assembler.tool_frame(
                    frame.counter, frame.torque_nm, frame.angle_deg, time_ns, bus_timed
                ),
                lane,
            )
        elif isinstance(frame, JointSensorsFrame):
            lane = self._lanes[frame.spindle]
            self._emit(lane.assembler.joint_frame(frame.counter, frame.force_n, time_ns), lane)
        elif isinstance(frame, ToolStatusFrame):
            self._tool_status(frame, time_ns, self._lanes[frame.spindle])
        elif isinstance(frame, ToolStageFrame):
            self._tool_stage(frame, time_ns, self._lanes[frame.spindle])
        elif isinstance(frame, CycleStartFrame):
            if frame.sync_id != self._sync_id:
                LOG.info("cycle %d starts (%d spindles)", frame.sync_id, frame.spindles)
            self._sync_id = frame.sync_id
        elif isinstance(frame, Rejected):
            self._rejected[frame.reason] += 1
            if LOG.isEnabledFor(logging.DEBUG):
                LOG.debug("rejected frame 0x%x: %s", message.arbitration_id, frame.reason)
        elif isinstance(frame, StopCommandFrame | StageCommandFrame):
            LOG.debug("%s from another node for run %d", type(frame).__name__, frame.run_id)

    def _emit(self, samples: list[AssembledSample], lane: SpindleLane) -> None:
        run_id = lane.run_id
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

    def _tool_status(self, frame: ToolStatusFrame, time_ns: int, lane: SpindleLane) -> None:
        try:
            state_name = ToolRunState(frame.state).name.lower()
        except ValueError:
            self._rejected["bad_state"] += 1  # never let a corrupt state restart the run
            return
        previous = lane.tool
        if previous == frame:
            return
        starts_run = frame.state == ToolRunState.RUNNING and (
            previous is None
            or previous.run_id != frame.run_id
            or previous.state != ToolRunState.RUNNING
        )
        if starts_run and frame.run_id in lane.started_runs:
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
            self._emit(lane.assembler.finish_run(), lane)  # leftovers belong to the old run
        if starts_run:
            lane.started_runs.append(frame.run_id)
            lane.assembler.start_run()
            lane.run_commands = lane.commands.run_commands()
            # a staged tool starts each run in its rundown (its ToolStage said so before)
            lane.stage = ("rundown", 0) if lane.run_commands == "staged" else None
            lane.sync_id = self._sync_id
        lane.tool = frame
        ended = frame.state in (ToolRunState.DONE, ToolRunState.ABORTED)
        commands = lane.commands
        stage, pulses = lane.stage if lane.stage is not None else (None, 0)
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
            commands=lane.run_commands,
            stage=stage if frame.state == ToolRunState.RUNNING else None,
            pulses=pulses,
            spindle=lane.spindle if self._multi else None,
            sync_id=lane.sync_id if self._multi else None,
        )
        self._tell(state)
        LOG.info("run %d: %s (program %d)", frame.run_id, state_name, frame.program_id)

    def _tool_stage(self, frame: ToolStageFrame, time_ns: int, lane: SpindleLane) -> None:
        """A staged tool's ToolStage: its features; a new stage of the running run is a new
        ToolState (running, with the stage), told to the predictor and the line."""
        lane.commands.heard(frame)
        tool = lane.tool
        if tool is None or tool.state != ToolRunState.RUNNING or frame.run_id != tool.run_id:
            return  # a run's features come before its start; stale ones are no news
        try:
            stage_name: ToolStageName = ToolStageCode(frame.stage).name.lower()  # type: ignore[assignment]
        except ValueError:
            self._rejected["bad_state"] += 1
            return
        if (stage_name, frame.pulses) == lane.stage:
            return
        lane.stage = (stage_name, frame.pulses)
        self._tell(
            ToolState(
                self.station_id,
                tool.run_id,
                tool.tool_id,
                tool.program_id,
                "running",
                time_ns,
                commands=lane.run_commands,
                stage=stage_name,
                pulses=frame.pulses,
                spindle=lane.spindle if self._multi else None,
                sync_id=lane.sync_id if self._multi else None,
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
        lane = self._lane_of(decision.run_id)
        if isinstance(decision, StopDecision):
            return lane.commands.stop(decision, lane.tool)
        return lane.commands.stage(decision, lane.tool)

    def _lane_of(self, run_id: int) -> SpindleLane:
        """The spindle running (or that ran last) ``run_id``; spindle 1 when none did (its
        commands count the decision late)."""
        if self._multi:
            for lane in self._lanes.values():
                if lane.tool is not None and lane.tool.run_id == run_id:
                    return lane
        return self._lanes[1]

    def send_stop(self, decision: StopDecision) -> bool:
        """Send StopCommand for ``decision`` if it is for the running run; once per run."""
        return self.send(decision)

    # -- counters ------------------------------------------------------------------------

    def stats(self) -> BusStats:
        lanes = self._lanes.values()
        pairing = PairingCounters()
        for lane in lanes:
            for name in PairingCounters.__dataclass_fields__:
                setattr(
                    pairing, name, getattr(pairing, name) + getattr(lane.assembler.counters, name)
                )
        commands = self._lanes[1].commands  # what the station may command: its spindles alike
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
            stop_commands=sum(lane.commands.stop_commands for lane in lanes),
            unsent_samples=self._unsent_samples(),
            late_decisions=sum(lane.commands.late_decisions for lane in lanes),
            bad_decisions=self._bad_decisions,
            started_ns=self._started_ns,
            repeated_runs=self._repeated_runs,
            tool_commands=commands.mode,
            tool_commands_note=commands.note,
            stage_commands=sum(lane.commands.stage_commands for lane in lanes),
            refused_stages=sum(lane.commands.refused_stages for lane in lanes),
        )
