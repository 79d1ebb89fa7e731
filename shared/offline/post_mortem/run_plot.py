"""The post-mortem PNG of one recorded run: the paper's figures for that run.

One page, a grid of panels, all over run time (s since the run's first
sample, the clock of ``Sample.time_ns``):

    row 1   torque with peaks T_max,j and the stop decision        Figure 10 (top)
    row 2   preload force with plateaus F_j and the stop decision  Figure 10 (bottom)
    row 3   f_ss, ΔF, ΔT per event                                 Figures 13-15 (top)
    row 4   K1, K2, K3 per event                                   Figures 13-15 (bottom)
    row 5   absolute prediction errors of T, F, t                  Figure 22
    row 6   relative prediction errors, eqs. 61-63                 Figure 23

With the joint (``joint`` metadata) and the motor speed (``program``) in the
file, the analytical envelopes (Figure 10), bounds (eqs. 21-26) and K bands
(eqs. 34-39) are drawn, at model time = run time + a shift anchored at the
first plateau (:class:`~shared.offline.post_mortem.post_mortem_run.ModelClock`); the
caption says so, and says when they are missing. A run a tool controller
tightened (:mod:`.controller_marks`) is drawn against the controller's own
torque window and target instead, from its result; never the station file's
program or the model of its joint. matplotlib (Agg) is imported inside the
functions: nothing at import time.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from shared.errors import naming
from shared.offline.post_mortem.post_mortem_errors import prediction_errors
from shared.offline.post_mortem.post_mortem_panels import (
    Bounds,
    draw_constants,
    draw_error_panels,
    draw_event_figures,
    draw_force,
    draw_torque,
)
from shared.offline.post_mortem.post_mortem_run import RecordedRun, read_run

if TYPE_CHECKING:
    from matplotlib.figure import Figure

FIGSIZE_IN = (18.0, 25.0)
DPI = 80


def build_figure(run: RecordedRun) -> Figure:
    """The report's figure of ``run`` (not drawn to a file; the caller closes it)."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=FIGSIZE_IN, dpi=DPI)
    grid = figure.add_gridspec(6, 3, height_ratios=(1.4, 1.4, 1, 1, 1, 1), hspace=0.5, wspace=0.28)
    bounds = Bounds.of(run)
    draw_torque(figure.add_subplot(grid[0, :]), run, bounds)
    force_axis = figure.add_subplot(grid[1, :])
    draw_force(force_axis, run, bounds)
    event_axes = [figure.add_subplot(grid[2, column]) for column in range(3)]
    draw_event_figures(event_axes, run, bounds)
    constant_axes = [figure.add_subplot(grid[3, column]) for column in range(3)]
    draw_constants(constant_axes, run, bounds)
    errors = prediction_errors(run.events)
    absolute = [figure.add_subplot(grid[4, column]) for column in range(3)]
    relative = [figure.add_subplot(grid[5, column]) for column in range(3)]
    draw_error_panels(absolute, relative, run, errors)
    for axis in figure.axes:
        axis.grid(True, alpha=0.3)
    figure.suptitle(_caption(run, bounds), fontsize=12, x=0.02, ha="left", y=0.997)
    figure.subplots_adjust(left=0.05, right=0.95, top=0.95, bottom=0.03)
    return figure


def _caption(run: RecordedRun, bounds: Bounds) -> str:
    state = "" if run.complete else "   DAMAGED FILE: its readable part only"
    force = "" if run.has_force else ", torque only (no preload force measured)"
    first = (
        f"{run.source.name}: run {run.run_id}, {len(run.samples)} samples, "
        f"{len(run.events)} stick-slip events{force}{state}"
    )
    if run.controller is not None:
        return (
            f"{first}\nA controller's run (its result: {run.controller.source}): drawn against "
            f"its own {run.controller.describe()}.\nNo analytical bounds "
            f"({run.model_missing}): measured values only."
        )
    if bounds.model is None or bounds.clock is None:
        why = run.model_missing or "no event to anchor model time"
        return f"{first}\nNo analytical bounds ({why}): measured values only."
    joint = run.joint.name if run.joint is not None else "?"
    return (
        f"{first}\nBounds: analytical model (Baramsky et al. 2018, eqs. 21-26, 34-39) of "
        f"'{joint}'\nat φ̇_m = {bounds.model.motor_speed_rad_s:g} rad/s; model time t = run time "
        f"{bounds.clock.offset_s:+.3f} s, anchored at the first event's {bounds.clock.anchor} "
        f"(Sec. 5.2 shifts by hand). Run time: s since the run's first sample."
    )


def draw_run(source: Path, target: Path, run_id: int | None = None) -> RecordedRun:
    """Draw the run into ``target`` (PNG); the run drawn (``complete``/``state``: was the
    file whole, and if not, how much of it was lost)."""
    import matplotlib

    matplotlib.use("Agg")

    run = read_run(source, run_id)
    figure = build_figure(run)
    with naming(target):
        figure.savefig(target, format="png")
    return run
