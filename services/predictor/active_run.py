"""One tightening run as the live service sees it: a core plus the run's bookkeeping.

Turns the core's plain outputs into :mod:`shared.messages` (events,
intensity, decision) and, at the end, the run's :class:`RunSummary`.
Pure: the wall-clock time of a decision is passed in by the caller.
"""

from __future__ import annotations

import math

from services.predictor.core import CoreDecision, CoreEvent, PredictorCore, PredictorSettings
from shared.config import Program
from shared.messages import (
    Intensity,
    RunSummary,
    Sample,
    StickSlipEvent,
    StopDecision,
    ToolState,
)

Outgoing = StickSlipEvent | Intensity | StopDecision


class ActiveRun:
    """The core of one (station, run_id) and what the summary needs."""

    def __init__(self, state: ToolState, program: Program, settings: PredictorSettings) -> None:
        self.state = state
        self.program = program
        self.settings = settings
        self.core = PredictorCore(settings)
        self.started_ns = state.time_ns
        self.samples = 0
        self.last: Sample | None = None
        self.decision: StopDecision | None = None

    def _time_s(self, time_ns: int) -> float:
        return (time_ns - self.started_ns) / 1e9

    def on_sample(self, sample: Sample, wall_ns: int) -> list[Outgoing]:
        """Feed one sample; the messages to publish because of it."""
        self.samples += 1
        self.last = sample
        force = sample.force_n if sample.force_n is not None else math.nan
        outputs = self.core.update(
            self._time_s(sample.time_ns), sample.torque_nm, force, sample.angle_deg
        )
        if not outputs:
            return []
        messages: list[Outgoing] = []
        for output in outputs:
            if isinstance(output, CoreEvent):
                messages.extend(self._event_messages(output, sample))
            else:
                messages.append(self._decision_message(output, sample, wall_ns))
        return messages

    def _event_messages(self, event: CoreEvent, sample: Sample) -> list[Outgoing]:
        station, run_id = self.state.station, self.state.run_id
        return [
            StickSlipEvent(
                station=station,
                run_id=run_id,
                index=event.index,
                time_ns=self.started_ns + round(event.time_s * 1e9),
                time_s=event.time_s,
                peak_torque_nm=event.peak_torque_nm,
                min_torque_nm=event.min_torque_nm,
                torque_drop_nm=event.torque_drop_nm,
                plateau_force_n=event.plateau_force_n,
                force_step_n=event.force_step_n,
                period_s=event.period_s,
                f_ss_hz=event.f_ss_hz,
                k1=event.k1,
                k2=event.k2,
                k3=event.k3,
                intensity=event.intensity,
                process_intensity=event.process_intensity,
                predictions=list(event.predictions),
            ),
            Intensity(
                station=station,
                run_id=run_id,
                time_ns=sample.time_ns,
                event_intensity=event.intensity if event.intensity is not None else 0.0,
                process_intensity=event.process_intensity,
            ),
        ]

    def _decision_message(
        self, decision: CoreDecision, sample: Sample, wall_ns: int
    ) -> StopDecision:
        torque = decision.torque_nm if math.isfinite(decision.torque_nm) else sample.torque_nm
        self.decision = StopDecision(
            station=self.state.station,
            run_id=self.state.run_id,
            time_ns=sample.time_ns,
            time_s=decision.time_s,
            reason=decision.reason,
            detail=decision.detail,
            torque_nm=torque,
            force_n=decision.force_n,
            predicted_force_n=decision.predicted_force_n,
            predicted_torque_nm=decision.predicted_torque_nm,
            decided_ns=wall_ns,
        )
        return self.decision

    def summary(self, end: ToolState) -> RunSummary:
        """The run's summary when the tool reports done or aborted."""
        last = self.last
        reached_force = last.force_n if last is not None and self.settings.has_force else None
        reached_torque = last.torque_nm if last is not None else 0.0
        error_pct = None
        target_force = self.program.target_force_n
        target_torque = self.program.target_torque_nm
        if reached_force is not None and target_force:
            error_pct = 100.0 * (reached_force - target_force) / target_force
        elif last is not None and not self.settings.has_force and target_torque:
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
            error_pct=error_pct,
            events=self.core.events,
            stop_reason=self.decision.reason if self.decision is not None else None,
            process_intensity=self.core.process_intensity,
            samples=self.samples,
            started_ns=self.started_ns,
            ended_ns=end.time_ns,
        )
