"""One tightening run as the live service sees it: a core plus the run's bookkeeping.

Turns the core's plain outputs into :mod:`shared.contract.messages` (events,
intensity, decision, a final stage's commands: :mod:`shared.stickslip.run_messages`)
and, at the end, the run's :class:`RunSummary`.
Pure: the wall-clock time of a decision is passed in by the caller.
"""

from __future__ import annotations

import math

from shared.config import Program
from shared.contract import (
    Intensity,
    PartSource,
    RunClock,
    RunSummary,
    Sample,
    StageDecision,
    StickSlipEvent,
    StopDecision,
    ToolCommandsName,
    ToolState,
)
from shared.stickslip import (
    CoreCommand,
    CoreDecision,
    EventFigures,
    PredictorCore,
    PredictorSettings,
    decision_message,
    event_messages,
    stage_message,
)

Outgoing = StickSlipEvent | Intensity | StopDecision | StageDecision


class ActiveRun:
    """The core of one (station, run_id) and what the summary needs."""

    def __init__(
        self,
        state: ToolState,
        program: Program,
        settings: PredictorSettings,
        part_id: str | None = None,
        part_source: PartSource = "unknown",
    ) -> None:
        """``part_id``: the part at the station when the run started (None: none known);
        ``part_source``: where it came from."""
        self.state = state
        self.program = program
        self.part_id = part_id
        self.part_source: PartSource = part_source if part_id is not None else "unknown"
        self.settings = settings
        self.core = PredictorCore(settings)
        self.started_ns = state.time_ns
        self.clock = RunClock(state.time_ns)
        self.samples = 0
        self.last: Sample | None = None  # the last sample whose torque was a measurement
        self.decision: StopDecision | None = None
        self.tool_pulses = 0  # the pulses the tool said it ran (ToolStage)
        self._torque_low, self._torque_high = settings.sensor_range.torque_nm

    def _time_s(self, sample: Sample) -> float:
        """The sample's run time: on the tool's own clock when it has one (no receive jitter)."""
        if sample.time_s is not None:
            return sample.time_s
        return self.clock.seconds(sample.time_ns)

    def on_sample(self, sample: Sample, wall_ns: int) -> list[Outgoing]:
        """Feed one sample; the messages to publish because of it."""
        self.samples += 1
        if self._torque_low <= sample.torque_nm <= self._torque_high:  # NaN is not
            self.last = sample  # what the run reached is measured, never a bad sample's value
        force = sample.force_n if sample.force_n is not None else math.nan
        outputs = self.core.update(self._time_s(sample), sample.torque_nm, force, sample.angle_deg)
        if not outputs:
            return []
        messages: list[Outgoing] = []
        for output in outputs:
            if isinstance(output, EventFigures):
                messages.extend(self._event_messages(output, sample))
            elif isinstance(output, CoreDecision):
                messages.append(self._decision_message(output, sample, wall_ns))
            else:
                messages.append(self._stage_message(output, sample, wall_ns))
        return messages

    def on_tool_stage(self, state: ToolState) -> None:
        """A staged tool's new stage: halted by itself (``holding``) before any decision."""
        if state.stage == "holding":
            self.core.on_tool_halted()
        self.tool_pulses = max(self.tool_pulses, state.pulses)

    def _stage_message(self, command: CoreCommand, sample: Sample, wall_ns: int) -> StageDecision:
        state = self.state
        return stage_message(
            state.station, state.run_id, command, sample.time_ns, sample.torque_nm, wall_ns
        )

    def _event_messages(self, event: EventFigures, sample: Sample) -> list[Outgoing]:
        state = self.state
        return list(event_messages(state.station, state.run_id, self.clock, event, sample.time_ns))

    def _decision_message(
        self, decision: CoreDecision, sample: Sample, wall_ns: int
    ) -> StopDecision:
        self.decision = decision_message(
            self.state.station,
            self.state.run_id,
            decision,
            sample.time_ns,
            sample.torque_nm,
            wall_ns,
        )
        return self.decision

    def _commands(self) -> ToolCommandsName | None:
        """What the station could command the tool in this run: ``staged`` only when its
        program has a final stage and the tool takes it; None when the tool did not say."""
        if self.state.commands is None:
            return None
        return "staged" if self.settings.final_stage is not None else "stop"

    def summary(self, end: ToolState) -> RunSummary:
        """The run's summary when the tool reports done or aborted.

        What stopped the tool is the acquisition's word (``end.stop_command``:
        the StopCommand it sent), not this predictor's: a decision that came
        too late, or never reached the tool, is reported as ``late_decision``.
        """
        last = self.last
        final = self.core.final_stage
        reached_force = last.force_n if last is not None and self.settings.has_force else None
        force_low, force_high = self.settings.sensor_range.force_n
        if reached_force is not None and not force_low <= reached_force <= force_high:
            reached_force = None  # the last force was no measurement
        reached_torque = last.torque_nm if last is not None else 0.0
        reached_angle = last.angle_deg if last is not None else None
        angle_low, angle_high = self.settings.sensor_range.angle_deg
        if reached_angle is not None and not angle_low <= reached_angle <= angle_high:
            reached_angle = None  # NaN, or beyond the sensor: no measurement
        error_pct = None
        target_force = self.program.target_force_n
        target_torque = self.program.target_torque_nm
        if reached_force is not None and target_force:
            error_pct = 100.0 * (reached_force - target_force) / target_force
        elif last is not None and target_torque and not self.settings.force_mode:
            # a torque target: on a torque-only station, or a program without a force target
            error_pct = 100.0 * (reached_torque - target_torque) / target_torque
        return RunSummary(
            station=self.state.station,
            run_id=self.state.run_id,
            tool_id=self.state.tool_id,
            program_id=self.state.program_id,
            tool_state=end.state,
            target_force_n=target_force,
            target_torque_nm=target_torque,
            reached_force_n=reached_force,
            reached_torque_nm=reached_torque,
            reached_angle_deg=reached_angle,
            error_pct=error_pct,
            events=self.core.events,
            stop_reason=end.stop_command,
            late_decision=(
                self.decision.reason
                if self.decision is not None and end.stop_command is None
                else None
            ),
            process_intensity=self.core.process_intensity,
            samples=self.samples,
            started_ns=self.started_ns,
            ended_ns=end.time_ns,
            commands=self._commands(),
            final_stage_s=final.switched_at_s if final is not None else None,
            pulses=max(self.tool_pulses, end.pulses),
            spindle=self.state.spindle,
            sync_id=self.state.sync_id,
        )
