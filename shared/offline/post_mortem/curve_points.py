"""Which samples of a curve a browser is sent: every one up to a bound, else the lowest and
the highest torque of each stretch (a peak or a slip's drop is never thinned away).

A tightening at 1 kHz is a few thousand samples and is sent whole; a run of minutes (up to
the recorder's file limits: 600 000 samples) is thinned to about ``max_points``, the same
samples for every series of the run, so torque, angle, preload and time stay paired;
:func:`json_column` is one series as JSON takes it.
"""

from __future__ import annotations

import itertools

import numpy as np
import numpy.typing as npt

#: the samples of one curve sent at most (about: a stretch gives its two extremes)
MAX_POINTS = 20_000
#: decimals of a time in seconds sent (a microsecond: samples are a millisecond apart)
TIME_DECIMALS = 6


def drawn_indices(
    torque_nm: npt.NDArray[np.float64], max_points: int = MAX_POINTS
) -> npt.NDArray[np.int64]:
    """The indices of the samples drawn, ascending: all of them when there are at most
    ``max_points``, else the first, the last and each stretch's lowest and highest torque
    (``max_points // 2`` stretches of equal length)."""
    count = len(torque_nm)
    if count <= max_points:
        return np.arange(count, dtype=np.int64)
    torque = np.nan_to_num(torque_nm, nan=0.0, posinf=0.0, neginf=0.0)
    edges = np.linspace(0, count, max(1, max_points // 2) + 1).astype(np.int64)
    kept = [0, count - 1]
    for low, high in itertools.pairwise(edges.tolist()):
        if high > low:
            stretch = torque[low:high]
            kept += [low + int(np.argmin(stretch)), low + int(np.argmax(stretch))]
    return np.unique(np.array(kept, dtype=np.int64))


def json_column(values: npt.NDArray[np.float64], decimals: int | None = None) -> list[float | None]:
    """A column as a list for JSON (``decimals``: rounded to them), a value that is not
    finite None (JSON has no NaN)."""
    if decimals is not None:
        values = np.round(values, decimals)
    finite = np.isfinite(values)
    listed: list[float | None] = values.tolist()
    if not finite.all():
        for n in np.flatnonzero(~finite):
            listed[n] = None
    return listed
