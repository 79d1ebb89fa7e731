"""What the bridge uses of a controller's messages: 0061/0065 results and 0900 curves.

- :func:`read_result`: a :class:`LastTighteningResult` (0061, any revision) or
  an :class:`OldTighteningResult` (0065, any revision) into
  :class:`ResultFigures`: the final torque and angle, the verdict, part and
  batch counter from either; limits and targets only from a 0061 (a 0065
  carries none: a fetched result is judged by the controller's own verdict). A
  window the controller leaves at 0 on both sides (min 0, max 0) is no window;
  a target of 0 is no target. A result with a sync tightening id (revision 2,
  other than 0) is a multi-spindle system's spindle's: its channel id (0061)
  is its spindle.
- :func:`read_curve`: a :class:`TraceCurve` (0900) of torque or angle into a
  :class:`Curve` (None for another trace type: current, ...); a curve without a
  time step, or with one no controller samples at, is refused
  (:class:`CurveRefusedError`).

Time stamps are the controller's local time, turned into ns with the
station's ``[openprotocol] timezone``. One that no clock holds (before
:data:`EARLIEST_NS`, or more than :data:`AHEAD_S` ahead of the bridge's
clock: a controller whose clock was never set, or set wrong) is replaced by
the time the bridge received it (``clock_refused``; the caller counts it).
"""

from __future__ import annotations

import datetime as dt
import math
import zoneinfo
from typing import Any, Final

from services.openprotocol.controller_tightening import Curve, ResultFigures
from shared.openprotocol import LastTighteningResult, TraceCurve, timestamp_ns

#: 0900 trace types the bridge uses (Open Protocol: 001 angle, 002 torque)
CURVE_KINDS = {1: "angle", 2: "torque"}
#: the earliest controller time taken (2000-01-01 UTC)
EARLIEST_NS: Final = int(dt.datetime(2000, 1, 1, tzinfo=dt.UTC).timestamp()) * 1_000_000_000
#: the furthest a controller's time may be ahead of the bridge's (a day: zones, drift)
AHEAD_S: Final = 86_400.0
#: time steps a controller samples a curve at (seconds): 1 µs to 1 s
TIME_STEP_S: Final = (1e-6, 1.0)
#: the longest curve taken (seconds)
LONGEST_CURVE_S: Final = 3600.0


class CurveRefusedError(ValueError):
    """A 0900 the bridge cannot place in time; the text says why."""


def controller_time_ns(text: str, timezone: str, now_ns: int) -> tuple[int, bool]:
    """The ns of the controller's time ``text``, and True; or ``now_ns`` and False when no
    clock holds it."""
    try:
        time_ns = timestamp_ns(text, zoneinfo.ZoneInfo(timezone))
    except (ValueError, OverflowError):
        return now_ns, False
    if not EARLIEST_NS <= time_ns <= now_ns + int(AHEAD_S * 1e9):
        return now_ns, False
    return time_ns, True


def result_key(message: Any) -> str:
    """What tells a result from another of the same id (0061 and 0065 give the same)."""
    return "|".join(
        str(value)
        for value in (
            message.timestamp,
            message.pset_id,
            f"{float(message.torque_nm):.2f}",
            int(message.angle_deg),
            int(bool(message.tightening_ok)),
            (message.vin or "").strip(),
        )
    )


def read_result(message: Any, timezone: str, filled: bool, now_ns: int) -> ResultFigures:
    """The figures of a 0061 or 0065 (``filled``: fetched with 0064)."""
    full = isinstance(message, LastTighteningResult)
    time_ns, clock_ok = controller_time_ns(message.timestamp, timezone, now_ns)
    torque_window = _window(message, "torque_min_nm", "torque_max_nm") if full else (None, None)
    angle_window = _window(message, "angle_min_deg", "angle_max_deg") if full else (None, None)
    sync_id = getattr(message, "sync_tightening_id", None)  # revision 2 on
    return ResultFigures(
        tightening_id=message.tightening_id,
        program_id=message.pset_id,
        time_ns=time_ns,
        ok=bool(message.tightening_ok),
        torque_nm=float(message.torque_nm),
        torque_min_nm=torque_window[0],
        torque_max_nm=torque_window[1],
        torque_target_nm=_target(message, "torque_final_target_nm") if full else None,
        angle_deg=float(message.angle_deg),
        angle_min_deg=angle_window[0],
        angle_max_deg=angle_window[1],
        angle_target_deg=_target(message, "angle_final_target_deg") if full else None,
        part_id=(message.vin or "").strip(),
        batch_size=getattr(message, "batch_size", None) or None,
        batch_counter=_batch_counter(message),
        strategy="",
        revision=message.revision,
        filled=filled,
        key=result_key(message),
        clock_refused=not clock_ok,
        sync_id=sync_id or None,
        spindle=(message.channel_id or None) if full and sync_id else None,
    )


def read_curve(message: TraceCurve, timezone: str, now_ns: int) -> tuple[Curve | None, bool]:
    """A torque or angle curve of a 0900 (None for any other trace type), and whether
    its time stamp was taken (False: no clock holds it, its end is placed at ``now_ns``).

    CurveRefusedError (OpenProtocolError: no time step) for a curve that cannot be placed
    in time."""
    kind = CURVE_KINDS.get(int(message.trace_type))
    if kind is None:
        return None, True
    time_step_s = message.time_step_s  # OpenProtocolError when it gives none
    low, high = TIME_STEP_S
    if not (math.isfinite(time_step_s) and low <= time_step_s <= high):
        raise CurveRefusedError(
            f"0900 of tightening {message.result_id}: time step {time_step_s:g} s is not "
            f"one a controller samples at ({low:g} to {high:g} s)"
        )
    duration_s = time_step_s * max(0, len(message.samples) - 1)
    if duration_s > LONGEST_CURVE_S:
        raise CurveRefusedError(
            f"0900 of tightening {message.result_id}: {duration_s:g} s of samples, more than "
            f"{LONGEST_CURVE_S:g} s"
        )
    start_ns, clock_ok = controller_time_ns(message.timestamp, timezone, now_ns)
    if not clock_ok:
        start_ns = now_ns - round(duration_s * 1e9)
    curve = Curve(
        tightening_id=message.result_id,
        kind=kind,
        start_ns=start_ns,
        time_step_s=time_step_s,
        values=tuple(float(value) for value in message.samples),
        sample_bytes=message.sample_bytes,
        coefficient=message.coefficient if message.samples else 1.0,
    )
    return curve, clock_ok


def _batch_counter(message: Any) -> int | None:
    """The batch counter; None where the controller keeps no batch (a batch size of 0, or
    no size given (0065 rev 1) and a counter of 0)."""
    size = getattr(message, "batch_size", None)
    counter = int(message.batch_counter)
    if size == 0 or (size is None and counter == 0):
        return None
    return counter


def _window(message: Any, low: str, high: str) -> tuple[float | None, float | None]:
    minimum, maximum = float(getattr(message, low)), float(getattr(message, high))
    if minimum == 0.0 and maximum == 0.0:
        return None, None
    return minimum, maximum


def _target(message: Any, name: str) -> float | None:
    value = float(getattr(message, name))
    return value if value > 0.0 else None
