"""What the bridge uses of a controller's messages: 0061/0065 results and 0900 curves.

- :func:`read_result`: a :class:`LastTighteningResult` (0061, any revision) or
  an :class:`OldTighteningResult` (0065) into :class:`ResultFigures`. Time
  stamps are the controller's local time, turned into ns with the station's
  ``[openprotocol] timezone``. A window the controller leaves at 0 on both
  sides (min 0, max 0) is no window; a target of 0 is no target. 0065 carries
  no limits or targets: a fetched result is judged by the controller's own
  verdict.
- :func:`read_curve`: a :class:`TraceCurve` (0900) of torque or angle into a
  :class:`Curve` (None for another trace type: current, ...).
"""

from __future__ import annotations

import zoneinfo
from typing import Any

from services.openprotocol.controller_tightening import Curve, ResultFigures
from shared.openprotocol.results import LastTighteningResult
from shared.openprotocol.timestamps import timestamp_ns
from shared.openprotocol.traces import TraceCurve

#: 0900 trace types the bridge uses (Open Protocol: 001 angle, 002 torque)
CURVE_KINDS = {1: "angle", 2: "torque"}


def read_result(message: Any, timezone: str, filled: bool) -> ResultFigures:
    """The figures of a 0061 or 0065 (``filled``: fetched with 0064)."""
    full = isinstance(message, LastTighteningResult)
    return ResultFigures(
        tightening_id=message.tightening_id,
        program_id=message.pset_id,
        time_ns=timestamp_ns(message.timestamp, zoneinfo.ZoneInfo(timezone)),
        ok=bool(message.tightening_ok),
        torque_nm=float(message.torque_nm),
        torque_min_nm=_window(message, "torque_min_nm", "torque_max_nm")[0] if full else None,
        torque_max_nm=_window(message, "torque_min_nm", "torque_max_nm")[1] if full else None,
        torque_target_nm=_target(message, "torque_final_target_nm") if full else None,
        angle_deg=float(message.angle_deg),
        angle_min_deg=_window(message, "angle_min_deg", "angle_max_deg")[0] if full else None,
        angle_max_deg=_window(message, "angle_min_deg", "angle_max_deg")[1] if full else None,
        angle_target_deg=_target(message, "angle_final_target_deg") if full else None,
        part_id=(message.vin or "").strip(),
        batch_size=getattr(message, "batch_size", None) or None,
        batch_counter=message.batch_counter if getattr(message, "batch_size", None) else None,
        strategy="",
        revision=message.revision,
        filled=filled,
    )


def read_curve(message: TraceCurve, timezone: str) -> Curve | None:
    """A torque or angle curve of a 0900; None for any other trace type."""
    kind = CURVE_KINDS.get(int(message.trace_type))
    if kind is None:
        return None
    return Curve(
        tightening_id=message.result_id,
        kind=kind,
        start_ns=timestamp_ns(message.timestamp, zoneinfo.ZoneInfo(timezone)),
        time_step_s=message.time_step_s,  # OpenProtocolError when it gives none
        values=tuple(float(value) for value in message.samples),
    )


def _window(message: Any, low: str, high: str) -> tuple[float | None, float | None]:
    minimum, maximum = float(getattr(message, low)), float(getattr(message, high))
    if minimum == 0.0 and maximum == 0.0:
        return None, None
    return minimum, maximum


def _target(message: Any, name: str) -> float | None:
    value = float(getattr(message, name))
    return value if value > 0.0 else None
