"""What a station commands a tool controller that runs a final stage, beyond the stop.

Re-exported by :mod:`shared.contract.messages`. Same rules as every message
there. A program may name a final stage (``[programs.final_stage]``:
:mod:`shared.config.final_stage`): the tool turns slower near the target, and
a torque-only station gives a short pulse back to the target when a slip took
a drop during the halt. What crosses the CAN bus for it (``StageCommand``,
``ToolStage``) is in the DBC and ``docs/reference/can-and-trace.md``; what
crosses zenoh is a :class:`StageDecision` on ``boltwatch/<st>/stage`` for
every command the station's predictor gives, recorded with the run.

The tool controller says what it can do (``ToolStage.Features``); the
acquisition tells the predictor with each run's :class:`ToolState`
(``commands``): a station whose controller does not accept them runs
stop-only, and never sends what the controller would not understand.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum
from typing import Literal

from shared.contract.message_fields import WIRE_CONFIG, Count, Id, Measured, StationId, TimeNs

#: what a station may command of its tool: stop only, or also a final stage and its pulses
ToolCommandsName = Literal["stop", "staged"]
#: the command of a StageDecision: the speed of the stage to run now (rundown, final); a
#: pulse from the halt; the halt of that pulse (stop); the end of the run (finish)
StageCommandName = Literal["rundown", "final", "pulse", "stop", "finish"]
#: why the station gave it
StageReasonName = Literal[
    "near_target",  # final: the torque (or the next plateau) is near the target
    "below_switch_point",  # rundown: a slip dropped the torque far below the switch point
    "lost_drop",  # pulse: the settled torque is a slip drop below the target
    "short_of_target",  # pulse: it is below the target by less than a drop
    "target_reached",  # stop: the pulse reached the target
    "settled",  # finish: the run settled where it should (or was stopped by another rule)
    "pulses_exhausted",  # finish: still short, and no pulse left
]
#: what a tool controller running a final stage is doing (ToolStage.Stage)
ToolStageName = Literal["rundown", "final", "pulse", "holding"]


class StageCommandCode(IntEnum):
    """``Command`` of the CAN ``StageCommand`` message (VAL_ table of the DBC)."""

    RUNDOWN = 0
    FINAL = 1
    PULSE = 2
    FINISH = 3


class StageReason(IntEnum):
    """``Reason`` of the CAN ``StageCommand`` message (VAL_ table of the DBC)."""

    UNSPECIFIED = 0
    NEAR_TARGET = 1
    BELOW_SWITCH_POINT = 2
    LOST_DROP = 3
    SHORT_OF_TARGET = 4
    SETTLED = 5
    PULSES_EXHAUSTED = 6


class ToolStageCode(IntEnum):
    """``Stage`` of the CAN ``ToolStage`` message (VAL_ table of the DBC)."""

    RUNDOWN = 0
    FINAL = 1
    PULSE = 2
    HOLDING = 3


#: ``ToolStage.Features`` bit: the controller takes StageCommand (final stage, pulse, finish)
FEATURE_STAGES = 0x01


@dataclass(frozen=True, slots=True)
class StageDecision:
    """A command the station's predictor gave a tool that runs a final stage.

    ``pulse``: the pulse a ``pulse`` starts or a ``stop`` halts (1, 2, ...); for a
    ``finish``, the pulses the run took; 0 otherwise. A ``stop`` goes out on CAN as a
    ``StopCommand``; the others as a ``StageCommand``.
    """

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    run_id: Id
    time_ns: TimeNs  # receive time of the sample at which it was decided
    time_s: float  # the same, since run start
    command: StageCommandName
    reason: StageReasonName
    detail: str
    torque_nm: Measured  # the torque it was decided on (pulse, finish: the settled torque)
    pulse: Count
    decided_ns: TimeNs  # wall clock when it was published
