"""The report's picture: per program a block of panels (matplotlib, Agg, no display).

Per program, one row per figure (final torque, angle, preload, process
intensity) with three panels: the X̄ chart (subgroup means, centre X̿,
limits LCL/UCL), the R or s chart, the histogram with the window (LSL, USL)
and the mean; then one row with the Pareto of NOK reasons (bars and the
cumulative share), the stop reasons and the histogram of stick-slip events
per run. The block's title says the program, runs, NOK rate and the Cpk of
each figure. A multi-spindle station's program has a block of its own for each
spindle after its own. matplotlib is imported inside the functions.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from shared.quality import FigureStatistics, ProgramStatistics, window_text

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure, SubFigure

ROW_HEIGHT_IN = 2.3
WIDTH_IN = 16.0
DPI = 80
ROWS_PER_PROGRAM = 5  # four figures and the row of reasons
NOTE_STYLE: dict[str, Any] = {"ha": "center", "va": "center", "color": "0.4"}
#: the events histogram draws one bar per count of events up to this many counts
MAX_EVENT_BARS = 100


def build_figure(programs: Sequence[ProgramStatistics], title: str) -> Figure:
    """The whole report as one figure (the caller draws it to a file)."""
    from matplotlib.figure import Figure

    height = ROW_HEIGHT_IN * ROWS_PER_PROGRAM * len(programs) + 0.8
    figure = Figure(figsize=(WIDTH_IN, height), dpi=DPI, layout="constrained")
    figure.suptitle(title, fontsize=14)
    blocks = figure.subfigures(len(programs), 1, squeeze=False)[:, 0]
    for block, program in zip(blocks, programs, strict=True):
        _draw_program(block, program)
    return figure


def png_bytes(figure: Figure) -> bytes:
    """The figure as PNG bytes."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png")
    return buffer.getvalue()


def cpk_text(statistics: FigureStatistics) -> str:
    """``Cpk 1.52`` or why it is not computed."""
    cap = statistics.capability
    return f"Cpk {cap.cpk:.2f}" if cap.cpk is not None else f"Cpk: {cap.not_computed}"


def _draw_program(block: SubFigure, program: ProgramStatistics) -> None:
    cpks = ", ".join(f"{figure.key} {cpk_text(figure)}" for figure in program.figures)
    block.suptitle(
        f"{program.name}: "
        f"{program.runs} runs, NOK {program.noks} ({100 * program.nok_rate:.1f} %)\n{cpks}",
        fontsize=11,
    )
    axes = block.subplots(ROWS_PER_PROGRAM, 3)
    for row, statistics in enumerate(program.figures):
        _draw_mean_chart(axes[row][0], statistics)
        _draw_spread_chart(axes[row][1], statistics)
        _draw_histogram(axes[row][2], statistics)
    _draw_pareto(axes[4][0], program.nok_reasons, program.runs)
    _draw_bars(axes[4][1], program.stop_reasons, "stop reasons (tool: stopped by itself)")
    _draw_events(axes[4][2], program.events_per_run)


def _label(statistics: FigureStatistics) -> str:
    unit = f" ({statistics.unit})" if statistics.unit else ""
    return f"{statistics.title}{unit}"


def _draw_mean_chart(axis: Axes, statistics: FigureStatistics) -> None:
    chart = statistics.chart
    title = f"X̄ chart: {_label(statistics)}"
    if chart is None:
        axis.set_title(title, fontsize=9)
        _empty(axis, f"{len(statistics.values)} runs: less than one subgroup")
        return
    label = f"X̿ {chart.centre:.4g}"
    _draw_chart(axis, title, chart.means, chart.centre, label, chart.mean_limits, "C0", chart.size)


def _draw_spread_chart(axis: Axes, statistics: FigureStatistics) -> None:
    chart = statistics.chart
    if chart is None:
        axis.set_title(f"R chart: {_label(statistics)}", fontsize=9)
        _empty(axis, "no subgroup")
        return
    title = f"{chart.spread} chart: {_label(statistics)}"
    label = f"{chart.spread}̄ {chart.spread_centre:.3g}"
    limits = chart.spread_limits
    _draw_chart(axis, title, chart.spreads, chart.spread_centre, label, limits, "C1", chart.size)


def _draw_chart(
    axis: Axes,
    title: str,
    points: Sequence[float],
    centre: float,
    centre_label: str,
    limits: Sequence[float],
    colour: str,
    subgroup_size: int,
) -> None:
    """One control chart: a point per subgroup, its centre line and control limits."""
    axis.set_title(title, fontsize=9)
    axis.plot(range(1, len(points) + 1), points, "o-", color=colour, markersize=3)
    axis.axhline(centre, color="C2", label=centre_label)
    for limit in limits:
        axis.axhline(limit, color="C3", linestyle="--")
    _subgroup_axis(axis, subgroup_size)


def _subgroup_axis(axis: Axes, size: int) -> None:
    from matplotlib.ticker import MaxNLocator

    axis.xaxis.set_major_locator(MaxNLocator(integer=True))
    axis.set_xlabel(f"subgroup of {size} runs", fontsize=8)
    axis.legend(fontsize=7, loc="upper right")


def _empty(axis: Axes, note: str) -> None:
    axis.set_axis_off()
    axis.text(0.5, 0.5, note, transform=axis.transAxes, **NOTE_STYLE)


def _draw_histogram(axis: Axes, statistics: FigureStatistics) -> None:
    cap = statistics.capability
    axis.set_title(
        f"{statistics.title}: {window_text(cap.lower, cap.upper)}, {cpk_text(statistics)}",
        fontsize=9,
    )
    if not len(statistics.values):
        _empty(axis, "not measured")
        return
    axis.hist(statistics.values, bins="auto", color="C0", alpha=0.8)
    for bound, name in ((cap.lower, "LSL"), (cap.upper, "USL")):
        if bound is not None:
            axis.axvline(bound, color="C3", linestyle="--", label=f"{name} {bound:g}")
    if cap.mean is not None:
        axis.axvline(cap.mean, color="C2", label=f"mean {cap.mean:.4g}")
    axis.set_xlabel(_label(statistics), fontsize=8)
    axis.legend(fontsize=7, loc="upper right")


def _draw_pareto(axis: Axes, reasons: Sequence[tuple[str, int]], runs: int) -> None:
    axis.set_title("Pareto of NOK reasons", fontsize=9)
    if not reasons:
        _empty(axis, f"no NOK in {runs} runs")
        return
    names = [name for name, _ in reasons]
    counts = [count for _, count in reasons]
    axis.bar(range(len(names)), counts, color="C3")
    axis.set_xticks(range(len(names)), names, rotation=20, ha="right", fontsize=7)
    axis.set_ylabel("runs", fontsize=8)
    share = axis.twinx()
    total = sum(counts)
    cumulative = [100.0 * sum(counts[: i + 1]) / total for i in range(len(counts))]
    share.plot(range(len(names)), cumulative, "o-", color="0.3", markersize=3)
    share.set_ylim(0, 105)
    share.set_ylabel("cumulative %", fontsize=8)


def _draw_bars(axis: Axes, counts: Sequence[tuple[str, int]], title: str) -> None:
    axis.set_title(title, fontsize=9)
    names = [name for name, _ in counts]
    axis.bar(range(len(names)), [count for _, count in counts], color="C4")
    axis.set_xticks(range(len(names)), names, rotation=20, ha="right", fontsize=7)
    axis.set_ylabel("runs", fontsize=8)


def _draw_events(axis: Axes, events: Sequence[int]) -> None:
    axis.set_title("stick-slip events per run", fontsize=9)
    if not events:
        _empty(axis, "no predictor saw these runs")
        return
    low, high = min(events), max(events)
    # a bar per count of events while they are few; beyond, numpy's bins (a million bars
    # would take minutes to draw)
    bins = (
        [value - 0.5 for value in range(low, high + 2)] if high - low <= MAX_EVENT_BARS else "auto"
    )
    axis.hist(events, bins=bins, color="C5")
    axis.set_xlabel("events", fontsize=8)
    axis.set_ylabel("runs", fontsize=8)
