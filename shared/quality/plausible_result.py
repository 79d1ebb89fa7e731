"""Whether a tightening result's figures can be a measurement at all: what statistics refuse.

A result read back (a recording, the results store) passed the contract's
decoder, which takes any finite float. A faulty node or a forgery can still
carry a final torque of 1e308 Nm: its mean and σ overflow, a histogram of it
has no bins, and one such result would spoil a program's report. Such a
result is refused, one by one and counted, never the report.

The bounds are far beyond any tightening tool, not a judgement of the joint:

- torque: |T| ≤ 1e6 Nm (the largest hydraulic wrenches give about 1e5 Nm);
- angle: |θ| ≤ 1e7 deg (nearly 28 000 turns);
- preload: |F| ≤ 1e9 N (the largest bolts hold about 1e7 N);
- stick-slip events: at most 1e6 a run (at 1 kHz, a run of 2000 s with an
  event every other sample);
- process intensity: 0 ≤ I ≤ 1e21 Nm²/s. Each event adds
  I_j = ΔT_j · |T_mean,j| · f_ss,j (eq. 67) ≥ 0, with ΔT ≤ 2e6 Nm, |T_mean|
  ≤ 1e6 Nm and f_ss ≤ 500 Hz (two samples at 1 kHz): ≤ 1e15 per event, times
  1e6 events.

A window bound (LSL, USL) beyond them is refused like a value: the report
draws it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from shared.contract import TighteningResult

TORQUE_LIMIT_NM = 1e6
ANGLE_LIMIT_DEG = 1e7
FORCE_LIMIT_N = 1e9
EVENTS_LIMIT = 1_000_000
INTENSITY_LIMIT = 1e21
#: the judged figures, in the order of :data:`~.program_columns.JUDGED_FIGURES`: name, bound
#: of the value and of the window, unit
FIGURE_LIMITS = (
    ("final torque", TORQUE_LIMIT_NM, "Nm"),
    ("final angle", ANGLE_LIMIT_DEG, "deg"),
    ("final preload", FORCE_LIMIT_N, "N"),
)

#: a judged figure: (value, window min, window max), each None when not given
Judged = tuple[float | None, float | None, float | None]


def figures_fault(
    judged: Sequence[Judged], events: float | None, intensity: float | None
) -> str | None:
    """Why these figures cannot be a measurement (which, its value, the bound); None: they
    can. ``judged``: torque, angle and preload as (value, min, max)."""
    for (name, limit, unit), figure in zip(FIGURE_LIMITS, judged, strict=True):
        for part, value in zip(("", " window min", " window max"), figure, strict=True):
            if value is not None and not (math.isfinite(value) and abs(value) <= limit):
                return f"{name}{part} {value:g} {unit}, expected within ±{limit:g} {unit}"
    if events is not None and not events <= EVENTS_LIMIT:
        return f"{events:.0f} stick-slip events, expected at most {EVENTS_LIMIT}"
    if intensity is not None and not (
        math.isfinite(intensity) and 0 <= intensity <= INTENSITY_LIMIT
    ):
        return f"process intensity {intensity:g}, expected from 0 to {INTENSITY_LIMIT:g} Nm²/s"
    return None


def implausible(result: TighteningResult) -> str | None:
    """Why ``result`` cannot be a measurement; None: it can (:func:`figures_fault`)."""
    judged = [
        (figure.value, figure.min, figure.max)
        for figure in (result.final_torque_nm, result.final_angle_deg, result.final_force_n)
    ]
    return figures_fault(judged, result.events, result.process_intensity)


def refusal_line(station: str, run_id: int, tool_id: int, why: str) -> str:
    """One line naming a refused result: station, run, tool, and why."""
    return f"station {station} run {run_id} (tool {tool_id}): {why}"
