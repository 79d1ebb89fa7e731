"""Which reading of a 0900's samples agrees with its result: byte order and scaling. Pure.

The public readings of 0900 disagree with what some controllers write: the
samples may be big- or little-endian, and a scaling parameter may be meant
the other way (a coefficient where a divisor was meant). Read wrong, a 25 Nm
tightening shows peaks of 322 Nm and the wear ledger takes thousands of
times its intensity. So a curve is never taken on trust: it is checked
against the result it belongs to, which the controller gives in ASCII:

- the **torque** curve's peak against the final torque: within
  :data:`TORQUE_LOW` to :data:`TORQUE_HIGH` times it (a controller's final
  torque is its peak in the final step; the curve may overshoot it a little),
  give or take two raw steps;
- the **angle** curve's end against the final angle: at most
  :data:`ANGLE_SLACK` of it (at least :data:`ANGLE_SLACK_DEG`) below it, or
  beyond it (a trace that counts from before the final step's angle
  threshold), on a curve that rises: at most :data:`ANGLE_FALLS` of its steps
  fall by more than two raw steps (samples read in the wrong byte order jump
  up and down, and may end near the final angle by chance).

:func:`check_curves` tries the candidate readings in order and takes the
first whose torque curve agrees (else, without a torque to check, whose angle
curve agrees). A curve that agrees with no reading is refused, never taken
wrong; a result without a final torque or angle leaves its curves unchecked
(read the first way). The bridge keeps the first reading that agreed for its
controller (:mod:`.bridge`).
"""

from __future__ import annotations

import itertools
import math
import struct
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Final, Literal

from services.openprotocol.controller_tightening import Curve, Tightening

ByteOrder = Literal["big", "little"]

TORQUE_LOW: Final = 0.8
TORQUE_HIGH: Final = 1.3
ANGLE_SLACK: Final = 0.2
ANGLE_SLACK_DEG: Final = 10.0
ANGLE_FALLS: Final = 0.05


@dataclass(frozen=True, slots=True)
class Reading:
    """How to read a 0900's samples: their byte order, and the scaling as declared or not."""

    byte_order: ByteOrder
    inverted_scale: bool = False  # the coefficient taken as a divisor, or the divisor as one

    def __str__(self) -> str:
        scale = "scaling inverted" if self.inverted_scale else "scaling as declared"
        return f"{self.byte_order}-endian, {scale}"

    @property
    def text(self) -> str:
        """What is kept in the bridge's file: ``big``, ``little/inverted``..."""
        return self.byte_order + ("/inverted" if self.inverted_scale else "")

    @classmethod
    def parse(cls, text: str) -> Reading | None:
        """The reading of :attr:`text`; None for anything else."""
        order, _, scale = text.partition("/")
        if order not in ("big", "little") or scale not in ("", "inverted"):
            return None
        return cls("big" if order == "big" else "little", scale == "inverted")


def readings(configured: Literal["auto", "big", "little"]) -> tuple[Reading, ...]:
    """The readings to try, in order: the byte order configured (``auto``: big first, as
    the public readings do), each with its scaling as declared, then inverted."""
    orders: tuple[ByteOrder, ...] = ("big", "little") if configured == "auto" else (configured,)
    return tuple(Reading(order, inverted) for inverted in (False, True) for order in orders)


@dataclass(frozen=True, slots=True)
class CheckedCurves:
    """A tightening's curves as they are to be published, and what was refused."""

    torque: Curve | None
    angle: Curve | None
    #: the reading that agreed with the result; None: nothing to check, or none agreed
    reading: Reading | None
    refused: tuple[str, ...]  # one line per refused curve: why


def check_curves(tightening: Tightening, candidates: Sequence[Reading]) -> CheckedCurves:
    """The tightening's curves read the first way that agrees with its result."""
    result = tightening.result
    torque, angle = tightening.torque, tightening.angle
    final_torque = result.torque_nm if result.torque_nm > 0 else None
    final_angle = result.angle_deg if result.angle_deg > 0 else None
    torque_checked = torque is not None and final_torque is not None
    angle_checked = angle is not None and final_angle is not None
    if not (torque_checked or angle_checked):
        first = candidates[0]
        return CheckedCurves(_read(torque, first), _read(angle, first), None, ())
    chosen = None
    if torque is not None and final_torque is not None:
        chosen = next((r for r in candidates if _torque_agrees(torque, r, final_torque)), None)
    if chosen is None and angle is not None and final_angle is not None:
        chosen = next((r for r in candidates if _angle_agrees(angle, r, final_angle)), None)
    if chosen is None:
        tried = "; ".join(str(r) for r in candidates)
        none_agree = tuple(
            f"{curve.kind} curve of tightening {result.tightening_id} agrees with its result "
            f"read no way ({tried}): refused"
            for curve in (torque, angle)
            if curve is not None
        )
        return CheckedCurves(None, None, None, none_agree)
    refused: list[str] = []
    kept_torque = _read(torque, chosen)
    if (
        torque is not None
        and final_torque is not None
        and not _torque_agrees(torque, chosen, final_torque)
    ):
        refused.append(_disagrees(torque, chosen, "peak", max(_values(torque, chosen)), result))
        kept_torque = None
    kept_angle = _read(angle, chosen)
    if (
        angle is not None
        and final_angle is not None
        and not _angle_agrees(angle, chosen, final_angle)
    ):
        refused.append(_disagrees(angle, chosen, "end", _values(angle, chosen)[-1], result))
        kept_angle = None
    return CheckedCurves(kept_torque, kept_angle, chosen, tuple(refused))


def _values(curve: Curve, reading: Reading) -> tuple[float, ...]:
    if not curve.sample_bytes:
        return curve.values
    factor = 1.0 / curve.coefficient if reading.inverted_scale else curve.coefficient
    order = ">" if reading.byte_order == "big" else "<"
    count = len(curve.sample_bytes) // 2
    return tuple(raw * factor for raw in struct.unpack(f"{order}{count}h", curve.sample_bytes))


def _step(curve: Curve, reading: Reading) -> float:
    """One raw step of the curve's samples, in its unit."""
    if not curve.sample_bytes:
        return 0.0
    return abs(1.0 / curve.coefficient if reading.inverted_scale else curve.coefficient)


def _read(curve: Curve | None, reading: Reading) -> Curve | None:
    if curve is None:
        return None
    return replace(curve, values=_values(curve, reading))


def _torque_agrees(curve: Curve, reading: Reading, final_nm: float) -> bool:
    values = _values(curve, reading)
    if not values:
        return False
    peak, slack = max(values), 2.0 * _step(curve, reading)
    return TORQUE_LOW * final_nm - slack <= peak <= TORQUE_HIGH * final_nm + slack


def _angle_agrees(curve: Curve, reading: Reading, final_deg: float) -> bool:
    values = _values(curve, reading)
    if not values or not all(math.isfinite(value) for value in values):
        return False
    step = 2.0 * _step(curve, reading)
    slack = max(ANGLE_SLACK * final_deg, ANGLE_SLACK_DEG) + step
    falls = sum(1 for before, after in itertools.pairwise(values) if after < before - step)
    return values[-1] >= final_deg - slack and falls <= ANGLE_FALLS * max(1, len(values) - 1)


def _disagrees(curve: Curve, reading: Reading, what: str, value: float, result: object) -> str:
    final = "final torque" if curve.kind == "torque" else "final angle"
    unit = "Nm" if curve.kind == "torque" else "deg"
    figure = getattr(result, "torque_nm" if curve.kind == "torque" else "angle_deg")
    return (
        f"{curve.kind} curve of tightening {curve.tightening_id}: its {what} {value:g} {unit} "
        f"does not agree with the {final} {figure:g} {unit} (read {reading}): refused"
    )
