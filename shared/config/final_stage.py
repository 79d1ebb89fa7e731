"""A program's final stage: the last part of the tightening at a lower speed, and its pulses.

A tool controller that does more than stop runs a program in stages, as real
ones do: the rundown at the program's ``motor_speed_rad_s``, then a final
stage at ``speed_rad_s``, slow enough that the tool halts within a small
step of the target and a slip is unlikely to come during the halt. The
switch point is found by the station's predictor (``switch = "predicted"``:
a few of the rundown's stick-ramp steps below the target, measured on the
joint) or by the controller itself at a fixed torque (``switch = "torque"``:
``switch_torque_nm``, a classic two-step program). Either way the station
decides when the tool halts.

Once the tool has halted and any slip has settled, a torque-only station sees
a lost slip drop as a settled torque below the target; it then commands a
short pulse at the final speed back to the target (a ``PulseCommand`` on
CAN: ``docs/reference/can-and-trace.md``), at most ``max_pulses`` times a run.
A controller holds a halted run open for ``hold_s`` waiting for a pulse or
the station's finish, and ends it by itself after that: a station that went
quiet never holds the tool.

``[[programs]]`` of a CAN station file::

    [programs.final_stage]
    speed_rad_s = 0.05          # the final stage's motor speed
    switch = "predicted"        # or "torque", with switch_torque_nm
    max_pulses = 2
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from shared.config.loading import StrictModel

#: the switch point a predicted switch aims at: this many of the rundown's stick-ramp steps
#: (one sample's torque rise) below the target (tuned on the torque-only benchmark's tuning
#: families: docs/explanation/algorithm.md, "A final stage")
DEFAULT_SWITCH_STEPS = 6.0


class FinalStage(StrictModel):
    """``[programs.final_stage]``: the final stage's speed, its switch point and its pulses."""

    speed_rad_s: float = Field(
        gt=0, le=50, description="the final stage's motor speed, below the program's"
    )
    switch: Literal["predicted", "torque"] = Field(
        default="predicted",
        description="who finds the switch point: the station's predictor ('predicted'), or "
        "the tool controller at switch_torque_nm ('torque')",
    )
    switch_torque_nm: float | None = Field(
        default=None, gt=0, description="switch = 'torque': the torque the controller switches at"
    )
    switch_steps: float = Field(
        default=DEFAULT_SWITCH_STEPS,
        gt=0,
        le=100,
        description="switch = 'predicted': switch this many rundown stick-ramp steps (one "
        "sample's torque rise each) below the target",
    )
    max_pulses: int = Field(
        default=2, ge=0, le=15, description="pulses back to the target a run may take at most"
    )
    pulse_below_pct: float = Field(
        default=1.0,
        gt=0,
        le=50,
        description="a settled torque (preload on a force station) further below the target "
        "than this share of it, in %, asks for a pulse",
    )
    hold_s: float = Field(
        default=0.5,
        ge=0.3,
        le=10,
        description="how long the tool controller holds a halted run open for a pulse or the "
        "station's finish before it ends the run by itself; at least 0.3 s: the station "
        "judges the settled torque within 0.25 s of a halt",
    )

    @model_validator(mode="after")
    def _switch_point_given(self) -> FinalStage:
        if self.switch == "torque" and self.switch_torque_nm is None:
            raise ValueError("switch = 'torque' needs switch_torque_nm (where the tool switches)")
        if self.switch == "predicted" and self.switch_torque_nm is not None:
            raise ValueError(
                "switch_torque_nm applies only to switch = 'torque' (a predicted switch point "
                "is found by the station)"
            )
        return self
