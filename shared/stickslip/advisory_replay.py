"""The predictor core over a run a tool controller stopped: what it saw, and would have decided.

Shared by ``boltwatch import`` (a controller's file) and the Open Protocol
bridge (a controller's live result and traces): both record a controller's
run with the same predictor output as a live run. The core the live service
and ``boltwatch predict`` run (:class:`~shared.stickslip.PredictorCore`)
is fed every sample of the run, and its outputs become the same messages a
live predictor publishes (:mod:`shared.stickslip.run_messages`): both call
:func:`replay_run`.

Settings: torque only (a controller measures no preload), the target is the
controller's final torque target, and ``advisory=True``: the controller, not
the predictor, stopped the tool, so the core goes on reporting events after
its decision, and the decision is recorded as ``StopDecision.advisory``
(decided on a replay, never acted on; its ``decided_ns`` is the deciding
sample's time). The ``RunSummary`` says ``stop_reason`` None (the tool stopped
by itself), with the replay's events and process intensity (what the wear
ledger adds up) and the controller's final torque as the reached torque. A
run without a usable torque target (none, or 0) is replayed without one:
events and intensity, no decision. A drop of no more than a few steps of the
torque's resolution is no event (``torque_resolution_nm``,
:mod:`.signal_resolution`).

A **loosening** (the tool turned back) is replayed on the magnitude of its
torque, the load on the tool whichever way it turns (a controller writes a
loosening's torque negative, or as its magnitude), without a target (there is
no torque to stop at), and its summary says ``operation`` loosening, its
reached torque the largest it measured (the breakaway).

Times: the core is fed each sample's time since the run's first sample, as
the live predictor is fed time since the run started, and as the trace CSVs
of ``import --csv`` and ``export`` count it: ``boltwatch predict`` on either
CSV reports the events recorded here.
"""

from __future__ import annotations

import math
from typing import Any

from shared.contract import RunClock, RunSummary, channels
from shared.stickslip.event_figures import EventFigures
from shared.stickslip.outputs import CoreDecision
from shared.stickslip.predictor_core import PredictorCore
from shared.stickslip.run_messages import decision_message, event_messages
from shared.stickslip.settings import PredictorSettings
from shared.stickslip.stopped_run import PredictorReplay, StoppedRun


def target_torque_nm(run: StoppedRun) -> float | None:
    """The controller's final torque target, if it has a usable one (> 0); a loosening
    has none."""
    target = run.target_torque_nm
    if run.operation == "loosening":
        return None
    return target if target is not None and math.isfinite(target) and target > 0.0 else None


def replay_settings(run: StoppedRun) -> PredictorSettings:
    """Torque only, to the controller's final torque target, advisory."""
    return PredictorSettings(
        target_torque_nm=target_torque_nm(run),
        has_force=False,
        advisory=True,
        torque_resolution_nm=run.torque_resolution_nm,
    )


def replayed_torque_nm(run: StoppedRun) -> list[float]:
    """The torque the core is fed: as measured; a loosening's magnitude."""
    if run.operation == "loosening":
        return [abs(torque) for torque in run.torque_nm]
    return list(run.torque_nm)


def replay_run(run: StoppedRun) -> PredictorReplay:
    """Feed every sample of ``run`` to a new core; its outputs as messages, and the summary."""
    core = PredictorCore(replay_settings(run))
    clock = RunClock(run.started_ns)
    station, run_id = run.station, run.run_id
    outputs: list[tuple[int, str, Any]] = []
    torque = replayed_torque_nm(run)
    samples = zip(run.run_time_s, run.times_ns, torque, run.angle_deg, strict=True)
    for index, (time_s, time_ns, torque_nm, angle_deg) in enumerate(samples):
        for output in core.update(time_s, torque_nm, math.nan, angle_deg):
            if isinstance(output, EventFigures):
                event, intensity = event_messages(station, run_id, clock, output, time_ns)
                outputs += [
                    (index, channels.EVENTS.topic, event),
                    (index, channels.INTENSITY.topic, intensity),
                ]
            elif isinstance(output, CoreDecision):
                decision = decision_message(
                    station, run_id, output, time_ns, torque_nm, time_ns, advisory=True
                )
                outputs.append((index, channels.DECISION.topic, decision))
    return PredictorReplay(outputs, _summary(run, core, torque))


def _summary(run: StoppedRun, core: PredictorCore, torque_nm: list[float]) -> RunSummary:
    target = target_torque_nm(run)
    reached = run.reached_torque_nm
    if reached is None or not math.isfinite(reached):  # the highest torque measured
        finite = [torque for torque in torque_nm if math.isfinite(torque)]
        reached = max(finite, default=0.0)
    error_pct = 100.0 * (reached - target) / target if target else None
    angle = run.reached_angle_deg
    return RunSummary(
        station=run.station,
        run_id=run.run_id,
        tool_id=run.tool_id,
        program_id=run.program_id,
        tool_state="done",
        target_force_n=None,
        target_torque_nm=target,
        reached_force_n=None,
        reached_torque_nm=reached,
        error_pct=error_pct,
        events=core.events,
        stop_reason=None,
        process_intensity=core.process_intensity,
        samples=len(run.times_ns),
        started_ns=run.started_ns,
        ended_ns=run.ended_ns,
        reached_angle_deg=angle if angle is not None and math.isfinite(angle) else None,
        operation=run.operation,
    )
