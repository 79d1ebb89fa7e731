"""Process capability of one figure of one program: mean, σ, Cp and Cpk against its window.

The figures of a plant's quality report (ISO 22514-2, the way tightening
tools such as ToolsNet report them), computed with numpy from the final
values of the runs::

    mean  = Σ x / n
    σ     = sqrt(Σ (x - mean)² / (n - 1))          (sample standard deviation, ddof=1:
                                                      every run's value, not within subgroups)
    Cp    = (USL - LSL) / (6 σ)                    (both bounds only)
    Cpk   = min(USL - mean, mean - LSL) / (3 σ)    (a one-sided window: that side only)

No window (no bound at all): Cp and Cpk are not computed, and the report
says so. Fewer than two values, or σ = 0: not computed either, said.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, slots=True)
class Capability:
    """Mean, σ, Cp, Cpk of ``n`` values against the window (``lower``, ``upper``)."""

    n: int
    mean: float | None
    sigma: float | None
    lower: float | None  # LSL; None: no lower bound
    upper: float | None  # USL; None: no upper bound
    cp: float | None
    cpk: float | None
    #: why Cp / Cpk are missing (None when Cpk is computed): said in the report
    not_computed: str | None


def capability(
    values: Sequence[float] | np.ndarray, lower: float | None, upper: float | None
) -> Capability:
    """The capability of ``values`` (None values already left out) against a window."""
    data = np.asarray(values, dtype=float)
    n = int(data.size)
    mean = float(np.mean(data)) if n else None
    sigma = float(np.std(data, ddof=1)) if n >= 2 else None
    why: str | None = None
    if lower is None and upper is None:
        why = "no window"
    elif n < 2 or sigma is None:
        why = f"{n} value{'s' if n != 1 else ''}: at least 2 needed"
    elif sigma == 0.0:
        why = "σ = 0"
    if why is not None or mean is None or sigma is None:
        return Capability(n, mean, sigma, lower, upper, None, None, why)
    sides = []
    if upper is not None:
        sides.append((upper - mean) / (3.0 * sigma))
    if lower is not None:
        sides.append((mean - lower) / (3.0 * sigma))
    cp = (upper - lower) / (6.0 * sigma) if upper is not None and lower is not None else None
    return Capability(n, mean, sigma, lower, upper, cp, min(sides), None)


def window_text(lower: float | None, upper: float | None) -> str:
    """``window [180, 240]``, ``window ≥ 180``, ``window ≤ 240`` or ``no window``."""
    if lower is not None and upper is not None:
        return f"window [{lower:g}, {upper:g}]"
    if lower is not None:
        return f"window ≥ {lower:g}"
    if upper is not None:
        return f"window ≤ {upper:g}"
    return "no window"
