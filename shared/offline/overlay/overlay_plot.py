"""The overlay figure: torque and preload of several runs over angle and over time.

Two panels side by side, over angle (deg) and over time (s), each with
torque above and preload below (when a run measured it). Each program's
windows are shaded boxes: over angle, torque min..max × angle min..max and
preload min..max × angle min..max; over time, the torque and preload
windows as bands (dash-dot edges).

The reference run is black and drawn on top; NOK runs are drawn in reds and
oranges, thicker, the others in blues and greens; the legend gives each run's
verdict from its ``TighteningResult`` (and why NOK), and says which runs
could not be aligned (drawn dotted). matplotlib (Agg) is imported inside the
functions.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from shared.errors import naming
from shared.offline.overlay.overlay_series import Overlay, ProgramWindows, RunSeries

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

FIGSIZE_IN = (17.0, 10.0)
DPI = 90
REFERENCE_COLOUR = "black"
WINDOW_COLOURS = ("tab:purple", "tab:olive", "tab:brown", "tab:cyan")
REASONS_SHOWN = 60  # characters of the NOK reasons in the legend


def run_colours(overlay: Overlay) -> dict[int, Any]:
    """A colour per run: black for the reference, reds for NOK, blues/greens for the rest."""
    from matplotlib import colormaps

    nok = [s.run_id for s in overlay.series if not s.reference and s.verdict == "NOK"]
    other = [s.run_id for s in overlay.series if not s.reference and s.verdict != "NOK"]
    colours: dict[int, Any] = {s.run_id: REFERENCE_COLOUR for s in overlay.series if s.reference}
    for ids, name in ((nok, "autumn"), (other, "winter")):
        for n, run_id in enumerate(ids):
            colours[run_id] = colormaps[name](0.85 * n / max(1, len(ids) - 1))
    return colours


def legend_label(series: RunSeries) -> str:
    label = f"run {series.run_id}"
    if series.spindle is not None:
        label += f" spindle {series.spindle}"
    if series.program_id is not None:
        label += f" (program {series.program_id})"
    label += f" {series.verdict}"
    if series.nok_reasons:
        reasons = series.nok_reasons
        if len(reasons) > REASONS_SHOWN:
            reasons = reasons[: REASONS_SHOWN - 1] + "…"
        label += f": {reasons}"
    if series.reference:
        label += "  [reference]"
    if series.note:
        label += f"  ({series.note})"
    return label


def build_figure(overlay: Overlay) -> Figure:
    """The overlay's figure (not drawn to a file; the caller closes it)."""
    from matplotlib.figure import Figure

    any_force = any(series.force_n is not None for series in overlay.series)
    figure = Figure(figsize=FIGSIZE_IN, dpi=DPI)
    rows = 2 if any_force else 1
    grid = figure.add_gridspec(rows, 2, height_ratios=(3, 2)[:rows], hspace=0.08, wspace=0.18)
    angle_torque = figure.add_subplot(grid[0, 0])
    time_torque = figure.add_subplot(grid[0, 1])
    angle_force = figure.add_subplot(grid[1, 0], sharex=angle_torque) if any_force else None
    time_force = figure.add_subplot(grid[1, 1], sharex=time_torque) if any_force else None
    colours = run_colours(overlay)
    for series in sorted(overlay.series, key=lambda s: s.reference):  # the reference on top
        style = _line_style(series)
        colour = colours[series.run_id]
        angle_torque.plot(series.angle_deg, series.torque_nm, color=colour, **style)
        time_torque.plot(series.time_s, series.torque_nm, color=colour, **style)
        if series.force_n is not None and angle_force is not None and time_force is not None:
            angle_force.plot(series.angle_deg, series.force_n / 1e3, color=colour, **style)
            time_force.plot(series.time_s, series.force_n / 1e3, color=colour, **style)
    for n, windows in enumerate(overlay.windows):
        colour = WINDOW_COLOURS[n % len(WINDOW_COLOURS)]
        angles = (windows.angle_min_deg, windows.angle_max_deg)
        torques = (windows.torque_min_nm, windows.torque_max_nm)
        forces_kn = (_kn(windows.force_min_n), _kn(windows.force_max_n))
        _window_box(angle_torque, angles, torques, colour)
        _window_box(time_torque, (None, None), torques, colour)
        if angle_force is not None and time_force is not None:
            _window_box(angle_force, angles, forces_kn, colour)
            _window_box(time_force, (None, None), forces_kn, colour)
    _label_axes(overlay, angle_torque, time_torque, angle_force, time_force)
    _legend(figure, overlay, colours)
    figure.suptitle(_caption(overlay), fontsize=11, x=0.01, ha="left", y=0.99)
    figure.subplots_adjust(left=0.05, right=0.98, top=0.91, bottom=0.2)
    return figure


def _line_style(series: RunSeries) -> dict[str, Any]:
    width = 2.4 if series.reference else (1.6 if series.verdict == "NOK" else 1.0)
    return {
        "linewidth": width,
        "linestyle": "-" if series.aligned else ":",
        "zorder": 4 if series.reference else (3 if series.verdict == "NOK" else 2),
    }


def _window_box(
    axis: Axes,
    x_bounds: tuple[float | None, float | None],
    y_bounds: tuple[float | None, float | None],
    colour: str,
) -> None:
    """A window as a shaded box with its edges; an open side (None) reaches the data's edge,
    and a window with no bound on either y side is not drawn."""
    from matplotlib.patches import Rectangle

    if y_bounds == (None, None):
        return
    limits = axis.dataLim
    low_x, high_x = _span(limits.x0, limits.x1, *x_bounds)
    low_y, high_y = _span(limits.y0, limits.y1, *y_bounds)
    size = (high_x - low_x, high_y - low_y)
    edge = "-." if x_bounds == (None, None) else "-"
    shade = Rectangle((low_x, low_y), *size, facecolor=colour, alpha=0.13, linewidth=0, zorder=1)
    axis.add_patch(shade)
    outline = Rectangle((low_x, low_y), *size, fill=False, edgecolor=colour, zorder=5)
    outline.set(linewidth=1.8, linestyle=edge)
    axis.add_patch(outline)


def _kn(force_n: float | None) -> float | None:
    return None if force_n is None else force_n / 1e3


def _span(
    low_data: float, high_data: float, low: float | None, high: float | None
) -> tuple[float, float]:
    """A window's bounds; an open side reaches the data's edge."""
    low_data = low_data if math.isfinite(low_data) else 0.0
    high_data = high_data if math.isfinite(high_data) else 1.0
    return (low if low is not None else low_data, high if high is not None else high_data)


def _label_axes(
    overlay: Overlay,
    angle_torque: Axes,
    time_torque: Axes,
    angle_force: Axes | None,
    time_force: Axes | None,
) -> None:
    frame = f"in run {overlay.frame_run}'s frame"
    angle_torque.set_title("over angle")
    time_torque.set_title("over time")
    angle_torque.set_ylabel("torque (Nm)")
    bottom_angle = angle_torque
    bottom_time = time_torque
    if angle_force is not None and time_force is not None:
        angle_force.set_ylabel("preload (kN)")
        angle_torque.tick_params(labelbottom=False)
        time_torque.tick_params(labelbottom=False)
        bottom_angle, bottom_time = angle_force, time_force
    bottom_angle.set_xlabel(f"angle (deg, {frame})")
    bottom_time.set_xlabel(f"time (s since the run's first sample, {frame})")
    for axis in (angle_torque, time_torque, angle_force, time_force):
        if axis is not None:
            axis.grid(True, alpha=0.3)


def _legend(figure: Figure, overlay: Overlay, colours: dict[int, Any]) -> None:
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles: list[Any] = [
        Line2D([], [], color=colours[s.run_id], label=legend_label(s), **_line_style(s))
        for s in overlay.series
    ]
    handles += [
        Patch(facecolor=WINDOW_COLOURS[n % len(WINDOW_COLOURS)], alpha=0.4,
              label=_window_label(windows))
        for n, windows in enumerate(overlay.windows)
    ]  # fmt: skip
    figure.legend(handles=handles, loc="lower left", ncols=2, fontsize=9, frameon=False,
                  bbox_to_anchor=(0.04, 0.0))  # fmt: skip


def _window_label(windows: ProgramWindows) -> str:
    def bounds(low: float | None, high: float | None, unit: str, scale: float = 1.0) -> str:
        if low is None and high is None:
            return "-"
        low_text = "…" if low is None else f"{low / scale:g}"
        high_text = "…" if high is None else f"{high / scale:g}"
        return f"{low_text} to {high_text} {unit}"

    return (
        f"program {windows.program_id} windows (run {windows.from_run}'s result): torque "
        f"{bounds(windows.torque_min_nm, windows.torque_max_nm, 'Nm')}, preload "
        f"{bounds(windows.force_min_n, windows.force_max_n, 'kN', 1e3)}, angle "
        f"{bounds(windows.angle_min_deg, windows.angle_max_deg, 'deg')}"
    )


def _caption(overlay: Overlay) -> str:
    counts = dict.fromkeys(("OK", "NOK", "no result"), 0)
    for series in overlay.series:
        counts[series.verdict] = counts.get(series.verdict, 0) + 1
    tally = ", ".join(f"{n} {verdict}" for verdict, n in counts.items() if n)
    unaligned = overlay.unaligned
    left = (
        f"; not aligned: run {', '.join(str(s.run_id) for s in unaligned)} (dotted)"
        if unaligned
        else ""
    )
    return (
        f"Overlay of {len(overlay.series)} runs ({tally}), aligned at: "
        f"{overlay.alignment.describe()}, onto run {overlay.frame_run}{left}\n"
        "Shaded: each program's windows (from its first run's TighteningResult; angles "
        "shifted with that run)."
    )


def save_figure(overlay: Overlay, target: Path) -> None:
    """Draw ``overlay`` into ``target`` (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    figure = build_figure(overlay)
    with naming(target):
        figure.savefig(target, format="png")
