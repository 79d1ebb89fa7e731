"""The core's plain outputs as the messages a station publishes (events, intensity, decision,
a final stage's commands).

One place for the conversion, so a live run (:class:`~services.predictor.active_run.ActiveRun`)
and a replayed one (``boltwatch import``) publish the same fields the same way.
Times: ``time_ns`` of an event is its peak's run time on the run's clock
(:class:`~shared.contract.run_clock.RunClock`); the intensity and the decision carry
the time of the sample that produced them.
"""

from __future__ import annotations

import math

from shared.contract import Intensity, RunClock, StageDecision, StickSlipEvent, StopDecision
from shared.stickslip.event_figures import EventFigures
from shared.stickslip.outputs import CoreCommand, CoreDecision


def stick_slip_event(
    station: str, run_id: int, clock: RunClock, event: EventFigures
) -> StickSlipEvent:
    """Event j as the wire message: its figures (all but the core's own
    ``current_force_n`` and ``detected_at_s``), the station, the run and the peak's ``time_ns``."""
    return StickSlipEvent(
        station=station,
        run_id=run_id,
        index=event.index,
        time_ns=clock.ns(event.time_s),
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
    )


def event_messages(
    station: str, run_id: int, clock: RunClock, event: EventFigures, sample_time_ns: int
) -> tuple[StickSlipEvent, Intensity]:
    """Event j and the intensity update it brings, confirmed at the sample of ``sample_time_ns``."""
    return (
        stick_slip_event(station, run_id, clock, event),
        Intensity(
            station=station,
            run_id=run_id,
            time_ns=sample_time_ns,
            event_intensity=event.intensity if event.intensity is not None else 0.0,
            process_intensity=event.process_intensity,
        ),
    )


def decision_message(
    station: str,
    run_id: int,
    decision: CoreDecision,
    sample_time_ns: int,
    sample_torque_nm: float,
    decided_ns: int,
    advisory: bool = False,
) -> StopDecision:
    """The decision taken at the sample of ``sample_time_ns`` (``advisory``: on a replay)."""
    torque = decision.torque_nm if math.isfinite(decision.torque_nm) else sample_torque_nm
    return StopDecision(
        station=station,
        run_id=run_id,
        time_ns=sample_time_ns,
        time_s=decision.time_s,
        reason=decision.reason,
        detail=decision.detail,
        torque_nm=torque,
        force_n=decision.force_n,
        predicted_force_n=decision.predicted_force_n,
        predicted_torque_nm=decision.predicted_torque_nm,
        decided_ns=decided_ns,
        advisory=advisory,
    )


def stage_message(
    station: str,
    run_id: int,
    command: CoreCommand,
    sample_time_ns: int,
    sample_torque_nm: float,
    decided_ns: int,
) -> StageDecision:
    """A final stage's command, given at the sample of ``sample_time_ns``."""
    torque = command.torque_nm if math.isfinite(command.torque_nm) else sample_torque_nm
    return StageDecision(
        station=station,
        run_id=run_id,
        time_ns=sample_time_ns,
        time_s=command.time_s,
        command=command.command,
        reason=command.reason,
        detail=command.detail,
        torque_nm=torque,
        pulse=command.pulse,
        decided_ns=decided_ns,
    )
