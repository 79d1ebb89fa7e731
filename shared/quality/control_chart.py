"""Shewhart control charts of one figure: X̄/R for subgroups up to 10 runs, X̄/s above.

The runs of a program, in the order they ended, are cut into consecutive
subgroups of ``size`` runs (an incomplete last subgroup is left out, and
counted). Per subgroup: its mean X̄ᵢ and its range Rᵢ (max - min) or its
standard deviation sᵢ (ddof=1). The centre lines are the grand mean X̿ and
R̄ (or s̄); the 3-sigma limits use the constants of ASTM E2587 (Montgomery,
*Introduction to Statistical Quality Control*, Appendix VI)::

    X̄/R:  UCL/LCL(X̄) = X̿ ± A2 R̄        UCL(R) = D4 R̄,  LCL(R) = D3 R̄
    X̄/s:  UCL/LCL(X̄) = X̿ ± A3 s̄        UCL(s) = B4 s̄,  LCL(s) = B3 s̄
          c4 = sqrt(2 / (n-1)) Γ(n/2) / Γ((n-1)/2)
          A3 = 3 / (c4 sqrt(n)),  B3 = max(0, 1 - 3 sqrt(1-c4²)/c4),  B4 = 1 + 3 sqrt(1-c4²)/c4

A2, D3 and D4 (n = 2..10) are the tabulated values (they come from the
distribution of the range of normal samples, d2 and d3); c4 is computed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

#: the largest subgroup charted with its range (X̄/R); larger ones use s (X̄/s)
LARGEST_RANGE_SUBGROUP = 10
#: n -> (A2, D3, D4), ASTM E2587 Table 1
RANGE_CONSTANTS: dict[int, tuple[float, float, float]] = {
    2: (1.880, 0.0, 3.267),
    3: (1.023, 0.0, 2.574),
    4: (0.729, 0.0, 2.282),
    5: (0.577, 0.0, 2.114),
    6: (0.483, 0.0, 2.004),
    7: (0.419, 0.076, 1.924),
    8: (0.373, 0.136, 1.864),
    9: (0.337, 0.184, 1.816),
    10: (0.308, 0.223, 1.777),
}


@dataclass(frozen=True, slots=True)
class ControlChart:
    """The X̄ chart and its R (or s) chart of one figure."""

    size: int  # runs per subgroup
    spread: str  # "R" or "s": what the second chart shows
    means: list[float]  # X̄ of each subgroup
    spreads: list[float]  # R or s of each subgroup
    centre: float  # X̿
    mean_limits: tuple[float, float]  # (LCL, UCL) of X̄
    spread_centre: float  # R̄ or s̄
    spread_limits: tuple[float, float]  # (LCL, UCL) of R or s
    left_out: int  # runs of an incomplete last subgroup

    @property
    def out_of_control(self) -> int:
        """Subgroups whose X̄ or spread lies outside its limits."""
        low, high = self.mean_limits
        spread_low, spread_high = self.spread_limits
        return sum(
            1
            for mean, spread in zip(self.means, self.spreads, strict=True)
            if not low <= mean <= high or not spread_low <= spread <= spread_high
        )


def c4(size: int) -> float:
    """The bias of s as an estimate of σ for ``size`` normal samples (via log-gamma)."""
    return math.sqrt(2.0 / (size - 1)) * math.exp(
        math.lgamma(size / 2.0) - math.lgamma((size - 1) / 2.0)
    )


def control_chart(values: Sequence[float] | np.ndarray, size: int) -> ControlChart | None:
    """The chart of ``values`` in subgroups of ``size`` (≥ 2); None below one full subgroup."""
    if size < 2:
        raise ValueError(f"a subgroup needs at least 2 runs, not {size}")
    data = np.asarray(values, dtype=float)
    groups = data.size // size
    if groups == 0:
        return None
    table = data[: groups * size].reshape(groups, size)
    means = table.mean(axis=1)
    centre = float(means.mean())
    if size <= LARGEST_RANGE_SUBGROUP:
        a2, d3, d4 = RANGE_CONSTANTS[size]
        spreads = table.max(axis=1) - table.min(axis=1)
        bar = float(spreads.mean())
        mean_width, spread_limits, spread = a2 * bar, (d3 * bar, d4 * bar), "R"
    else:
        bias = c4(size)
        spreads = table.std(axis=1, ddof=1)
        bar = float(spreads.mean())
        a3 = 3.0 / (bias * math.sqrt(size))
        b = 3.0 * math.sqrt(1.0 - bias**2) / bias
        mean_width, spread_limits, spread = a3 * bar, (max(0.0, 1 - b) * bar, (1 + b) * bar), "s"
    return ControlChart(
        size=size,
        spread=spread,
        means=[float(mean) for mean in means],
        spreads=[float(value) for value in spreads],
        centre=centre,
        mean_limits=(centre - mean_width, centre + mean_width),
        spread_centre=bar,
        spread_limits=spread_limits,
        left_out=int(data.size - groups * size),
    )
