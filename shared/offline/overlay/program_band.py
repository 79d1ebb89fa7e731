"""A program's band: the lowest, highest and median torque (and preload) of its recent runs,
over angle and over time, to draw one run against (the line's page).

The runs are put in the frame of the run drawn against them, aligned as the overlay
aligns (:func:`~.overlay_document.aligned`; a run that never reaches the point is left
out, named in ``left_out``). Each run's curve is then read at :data:`GRID_POINTS` x values
spanning every run (linear between its samples, nothing outside its own span); the
band holds where at least :data:`MIN_RUNS` runs reach, None elsewhere. Over angle a
run's curve is taken as its angle rose (its running highest: the sensor's noise or a
turn back would fold the curve onto itself); a sample without a preload is left out of
that run's preload curve.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from shared.offline.overlay.overlay_alignment import Alignment
from shared.offline.overlay.overlay_document import AlignedRun, aligned
from shared.offline.overlay.overlay_run import FloatArray, OverlayRun
from shared.offline.post_mortem.curve_points import TIME_DECIMALS, json_column

#: x values the band is given at
GRID_POINTS = 400
#: runs that must reach an x for the band to hold there
MIN_RUNS = 2


def program_band_document(
    run: tuple[str, OverlayRun],
    others: Sequence[tuple[str, OverlayRun]],
    alignment: Alignment,
    grid_points: int = GRID_POINTS,
) -> dict[str, Any]:
    """The band of ``others`` (key, run) in the frame of ``run`` (key, run)."""
    key = run[0]
    mine = [(k, r) for k, r in others if k != key]
    _, placed = aligned([run, *mine], key, alignment)
    used = [p for p in placed if p.key != key and p.aligned]
    return {
        "alignment": alignment.describe(),
        "frame": key,
        "runs": [p.key for p in used],
        "left_out": [{"key": p.key, "note": p.note} for p in placed if not p.aligned],
        "over_angle": _band(used, "angle", grid_points),
        "over_time": _band(used, "time", grid_points),
    }


def _band(runs: Sequence[AlignedRun], axis: str, grid_points: int) -> dict[str, Any] | None:
    curves = [_x_of(run, axis) for run in runs]
    if len(curves) < MIN_RUNS:
        return None
    low = min(float(x[0]) for x in curves)
    high = max(float(x[-1]) for x in curves)
    grid = np.linspace(low, high, grid_points)
    torque = np.vstack(
        [_on(grid, x, run.run.torque_nm) for x, run in zip(curves, runs, strict=True)]
    )
    forces = [
        _on(grid, x, run.run.force_n)
        for x, run in zip(curves, runs, strict=True)
        if run.run.force_n is not None
    ]
    force = _figures(np.vstack(forces)) if len(forces) >= MIN_RUNS else None
    decimals = TIME_DECIMALS if axis == "time" else None
    return {"x": json_column(grid, decimals), "torque_nm": _figures(torque), "force_n": force}


def _x_of(run: AlignedRun, axis: str) -> FloatArray:
    if axis == "time":
        return run.time_s
    result: FloatArray = np.maximum.accumulate(run.angle_deg)
    return result


def _on(grid: FloatArray, x: FloatArray, y: FloatArray) -> FloatArray:
    """``y`` over ``x`` read at ``grid`` (NaN outside ``x``'s span and where ``y`` has none)."""
    finite = np.isfinite(x) & np.isfinite(y)
    if finite.sum() < 2:
        return np.full(len(grid), np.nan)
    values: FloatArray = np.interp(grid, x[finite], y[finite], left=np.nan, right=np.nan)
    return values


def _figures(matrix: FloatArray) -> dict[str, list[float | None]]:
    """Per x: lowest, highest, median of the runs that reach it (at least MIN_RUNS)."""
    enough = np.isfinite(matrix).sum(axis=0) >= MIN_RUNS
    reached = matrix[:, enough]
    figures = {}
    for name, figure in (("low", np.nanmin), ("high", np.nanmax), ("median", np.nanmedian)):
        values = np.full(matrix.shape[1], np.nan)
        values[enough] = figure(reached, axis=0)
        figures[name] = json_column(values)
    return figures
