"""What the core decides: at most one :class:`CoreDecision` per run, and the commands of a
final stage (:class:`CoreCommand`).

With :class:`~.event_figures.EventFigures` (one per stick-slip event) it is
what the core reports: plain values (no station, no run id, no wall clock);
the service wraps them into :mod:`shared.contract.messages` types
(:mod:`shared.stickslip.run_messages`), ``boltwatch predict`` prints them.
"""

from __future__ import annotations

from dataclasses import dataclass

from shared.contract import StageCommandName, StageReasonName, StopReasonName


@dataclass(frozen=True, slots=True)
class CoreDecision:
    """Stop the tool now, decided at the sample at ``time_s``."""

    time_s: float
    reason: StopReasonName
    detail: str
    torque_nm: float
    force_n: float | None
    predicted_force_n: float | None  # the force the stop is predicted to land on (force target)
    predicted_torque_nm: float | None = None  # the torque it lands on (torque target)


@dataclass(frozen=True, slots=True)
class CoreCommand:
    """A command for a tool controller that runs a final stage, decided at ``time_s``
    (:mod:`.final_stage_run`): switch speed, pulse, halt a pulse, finish the run."""

    time_s: float
    command: StageCommandName
    reason: StageReasonName
    detail: str
    torque_nm: float  # the measured torque it was decided on (pulse, finish: the settled one)
    pulse: int = 0  # the pulse it starts or halts (pulse, stop), pulses so far (finish)
