"""The predictor core over an imported controller run: what it saw, and would have decided.

``boltwatch import`` records a controller run with the same predictor output
as a live run: the core the live service and ``boltwatch predict`` run
(:class:`~services.predictor.core.PredictorCore`) is fed every sample of the
run, and its outputs become the same messages a live predictor publishes
(:mod:`services.predictor.run_messages`). The recorder may not import the
predictor (services meet on zenoh only), so the command line, which knows
every service, builds them here and hands them to the recorder's import.

Settings: torque only (the controller measures no preload), the target is
the last step's ``TF Torque`` nominal (the torque the controller tightened
to), and ``advisory=True``: the controller, not the predictor, stopped the
tool, so the core goes on reporting events after its decision, and the
decision is recorded as ``StopDecision.advisory`` (decided on a replay, never
acted on; its ``decided_ns`` is the deciding sample's time). The run's
``RunSummary`` says ``stop_reason`` None (the tool stopped by itself), with
the replay's events and process intensity (what the wear ledger adds up) and
the controller's final torque (the last step's ``TF Torque`` actual) as the
reached torque. A run whose last step has no torque target is replayed
(or a nominal of 0) without one: events and intensity, no decision.

Times: the core is fed each sample's time since the run's first sample, as
the live predictor is fed time since the run started, and as the trace CSVs
of ``import --csv`` and ``export`` count it: ``boltwatch predict`` on either
CSV reports the events recorded here.
"""

from __future__ import annotations

import math
from typing import Any

from services.predictor.core import EventFigures, PredictorCore, PredictorSettings
from services.predictor.run_messages import decision_message, event_messages
from services.recorder.controller_import.controller_import import PredictorReplay, run_end_ns
from services.recorder.controller_import.controller_run import ControllerRun
from shared import channels
from shared.messages import RunSummary
from shared.run_clock import RunClock


def target_torque_nm(run: ControllerRun) -> float | None:
    """The last step's ``TF Torque`` nominal, if it has a usable one (> 0)."""
    nominal = run.final_torque_nominal_nm
    return nominal if nominal is not None and nominal > 0.0 else None


def replay_settings(run: ControllerRun) -> PredictorSettings:
    """Torque only, to the controller's final torque target, advisory."""
    return PredictorSettings(target_torque_nm=target_torque_nm(run), has_force=False, advisory=True)


def replay_run(station: str, run: ControllerRun) -> PredictorReplay:
    """Feed every sample of ``run`` to a new core; its outputs as messages, and the summary."""
    core = PredictorCore(replay_settings(run))
    clock = RunClock(run.started_ns)
    outputs: list[tuple[int, str, Any]] = []
    samples = zip(run.run_time_s, run.times_ns, run.torque_nm, run.angle_deg, strict=True)
    for index, (time_s, time_ns, torque_nm, angle_deg) in enumerate(samples):
        for output in core.update(time_s, torque_nm, math.nan, angle_deg):
            if isinstance(output, EventFigures):
                event, intensity = event_messages(station, run.run_id, clock, output, time_ns)
                outputs += [
                    (index, channels.EVENTS.topic, event),
                    (index, channels.INTENSITY.topic, intensity),
                ]
            else:
                decision = decision_message(
                    station, run.run_id, output, time_ns, torque_nm, time_ns, advisory=True
                )
                outputs.append((index, channels.DECISION.topic, decision))
    return PredictorReplay(outputs, _summary(station, run, core))


def _summary(station: str, run: ControllerRun, core: PredictorCore) -> RunSummary:
    target = target_torque_nm(run)
    reached = run.final_torque_actual_nm
    if reached is None:  # no torque function in the last step: the highest torque measured
        reached = max(run.torque_nm)
    error_pct = 100.0 * (reached - target) / target if target else None
    return RunSummary(
        station=station,
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
        samples=len(run),
        started_ns=run.started_ns,
        ended_ns=run_end_ns(run),
    )
