"""An imported controller run as the predictor's replay takes it (``boltwatch import``).

The replay itself is the stick-slip library's (:mod:`shared.stickslip.advisory_replay`,
shared with the Open Protocol bridge); here a :class:`ControllerRun` becomes a
:class:`~shared.stickslip.stopped_run.StoppedRun`.

A CS351 run's target is its last step's ``TF Torque`` nominal (the torque the
controller tightened to), its reached torque the ``TF Torque`` actual (the
highest torque measured where the last step has none); the resolution of its
torque and whether it was a loosening come with it.
"""

from __future__ import annotations

from shared.offline.controller_import.controller_run import ControllerRun
from shared.stickslip import PredictorReplay, StoppedRun
from shared.stickslip import replay_run as advisory_replay


def stopped_run(station: str, run: ControllerRun) -> StoppedRun:
    """The run's samples, identity, torque target and final torque."""
    return StoppedRun(
        station=station,
        run_id=run.run_id,
        tool_id=run.tool_id,
        program_id=run.program_id,
        started_ns=run.started_ns,
        ended_ns=run.ended_ns,
        times_ns=run.times_ns,
        run_time_s=run.run_time_s,
        torque_nm=run.torque_nm,
        angle_deg=run.angle_deg,
        target_torque_nm=run.final_torque_nominal_nm,
        reached_torque_nm=run.final_torque_actual_nm,
        torque_resolution_nm=run.torque_resolution_nm,
        operation=run.operation,
    )


def replay_run(station: str, run: ControllerRun) -> PredictorReplay:
    """The predictor's advisory replay of an imported run."""
    return advisory_replay(stopped_run(station, run))
