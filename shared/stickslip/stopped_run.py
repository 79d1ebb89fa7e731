"""A run a tool controller tightened and stopped, and what the predictor makes of it after.

A controller's run (imported from its file by ``boltwatch import``, or received
live from it by the Open Protocol bridge) was stopped by the controller, not by
boltwatch: the predictor can only replay it after the fact
(:func:`shared.stickslip.advisory_replay.replay_run`); these are the types it
takes and gives.

- :class:`StoppedRun`: the run as the replay takes it: identity, samples on the
  controller's own clock, the controller's torque target and final torque;
- :class:`PredictorReplay`: the core's outputs as the messages a live station
  publishes (events, intensities, the advisory decision), each with the index
  of the sample after which it came, and the run's ``RunSummary``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from shared.contract import RunOperation, RunSummary


@dataclass(frozen=True, slots=True)
class StoppedRun:
    """One run of a controller's tool, as the predictor's replay takes it.

    The four sample columns have one entry per sample, in order:
    ``times_ns`` (ns since the epoch), ``run_time_s`` (s since the run's first
    sample), torque (Nm) and angle (deg); they may be empty (a result whose
    traces never came): the summary then has no events and the controller's
    final torque.
    """

    station: str
    run_id: int
    tool_id: int
    program_id: int
    started_ns: int
    ended_ns: int
    times_ns: Sequence[int]
    run_time_s: Sequence[float]
    torque_nm: Sequence[float]
    angle_deg: Sequence[float]
    #: the torque the controller tightened to (its final target); None or <= 0: none
    target_torque_nm: float | None
    #: the controller's own final torque; None: the highest torque of the samples
    reached_torque_nm: float | None
    #: the controller's own final angle (deg), when it gives one
    reached_angle_deg: float | None = None
    #: the step the controller writes its torque to (Nm; 0: not known)
    torque_resolution_nm: float = 0.0
    #: a loosening (the tool turned back) or a tightening
    operation: RunOperation = "tightening"


@dataclass(frozen=True, slots=True)
class PredictorReplay:
    """What the predictor core made of a run, to publish or record beside its samples."""

    #: (index of the sample after which it was published, topic, message), in order
    outputs: list[tuple[int, str, Any]]
    summary: RunSummary
