"""The table ``boltwatch up`` prints: one row per tightening run, for a plant engineer.

With several stations (``--stations N``) the first column names the station.
The ``result`` column is the run's verdict (its ``TighteningResult`` on
``boltwatch/<st>/results``: OK, or NOK against the program's windows); ``-``
when no result arrived for the run. The last column, ``part``, is the part
the result names (the id the line scanned before the run, a controller's
VIN), left-aligned as ids are read; ``-`` when it names none. A run whose
final stage gave pulses back to the target says so after its stop reason
(``target_reached+pulse``, ``+2pulses``). A multi-spindle station's rows
say each run's spindle after its run id (``spindles``), and the totals its
cycles' common results.
"""

from __future__ import annotations

from shared.contract import BridgeStats, CycleResult, RunSummary, TighteningResult

COLUMNS = (
    ("run", 10),
    ("prog", 4),
    ("target", 10),
    ("reached", 10),
    ("error %", 8),
    ("result", 6),
    ("events", 6),
    ("stop reason", 20),
    ("intensity", 10),
    ("samples", 7),
)
#: the last column, left-aligned, as wide as its part ids
PART_TITLE = "part"


STATION_WIDTH = 8
#: the spindle column of a multi-spindle station, after the run
SPINDLE_COLUMN = ("spindle", 7)


def _columns(spindles: bool) -> tuple[tuple[str, int], ...]:
    return (COLUMNS[0], SPINDLE_COLUMN, *COLUMNS[1:]) if spindles else COLUMNS


def header(station_column: bool = False, spindles: bool = False) -> str:
    columns = _columns(spindles)
    line = "  ".join(f"{title:>{width}}" for title, width in columns) + f"  {PART_TITLE}"
    if station_column:
        line = f"{'station':>{STATION_WIDTH}}  {line}"
    return f"{line}\n{'-' * len(line)}"


def row(
    summary: RunSummary,
    station_column: bool = False,
    result: TighteningResult | None = None,
    spindles: bool = False,
) -> str:
    if summary.target_force_n is not None:
        target = f"{summary.target_force_n / 1000:.2f} kN"
        reached = _kilo(summary.reached_force_n, "kN")
    else:
        target = f"{summary.target_torque_nm or 0:.1f} Nm"
        reached = f"{summary.reached_torque_nm:.1f} Nm"
    error = "-" if summary.error_pct is None else f"{summary.error_pct:+.2f}"
    reason = summary.stop_reason or f"tool ({summary.tool_state})"
    if summary.pulses:  # a final stage's pulses back to the target
        reason += "+pulse" if summary.pulses == 1 else f"+{summary.pulses}pulses"
    cells: tuple[str, ...] = (
        str(summary.run_id),
        str(summary.program_id),
        target,
        reached,
        error,
        result.result if result is not None else "-",
        str(summary.events),
        reason,
        f"{summary.process_intensity:.3g}",
        str(summary.samples),
    )
    if spindles:
        cells = (cells[0], "-" if summary.spindle is None else str(summary.spindle), *cells[1:])
    columns = _columns(spindles)
    line = "  ".join(f"{cell:>{width}}" for cell, (_, width) in zip(cells, columns, strict=True))
    part = result.part_id if result is not None and result.part_id else "-"
    line = f"{line}  {part}"
    return f"{summary.station:>{STATION_WIDTH}}  {line}" if station_column else line


def _kilo(value: float | None, unit: str) -> str:
    return "-" if value is None else f"{value / 1000:.2f} {unit}"


def totals(
    summaries: list[RunSummary],
    results: list[TighteningResult] | None = None,
    cycles: list[CycleResult] | None = None,
) -> str:
    """One line: runs, mean and worst |error|, how many were OK and NOK, on how many parts
    (a multi-spindle station: its cycles, how many were OK and NOK)."""
    errors = [abs(s.error_pct) for s in summaries if s.error_pct is not None]
    line = f"{len(summaries)} runs"
    if errors:
        line += f", |error| mean {sum(errors) / len(errors):.2f} %, worst {max(errors):.2f} %"
    if results is not None:
        nok = sum(1 for result in results if result.result == "NOK")
        line += f", {len(results) - nok} OK, {nok} NOK"
        if len(results) < len(summaries):
            line += f", {len(summaries) - len(results)} without a result"
        parts = {result.part_id for result in results if result.part_id}
        if parts:
            line += f", {len(parts)} part{'s' if len(parts) != 1 else ''}"
    if cycles:
        nok = sum(1 for cycle in cycles if cycle.result == "NOK")
        line += f"; {len(cycles)} cycles, {len(cycles) - nok} OK, {nok} NOK"
    staged = [s for s in summaries if s.commands == "staged"]
    if staged:
        pulsed = sum(1 for s in staged if s.pulses)
        line += f", {len(staged)} in a final stage ({pulsed} took a pulse)"
    return line


def bridge_line(stats: BridgeStats) -> str:
    """The counters of an Open Protocol bridge, as ``up`` reports them at the end."""
    faults = {
        "link drops": stats.link_drops,
        "repeated": stats.repeated_results,
        "garbage bytes": stats.garbage_bytes,
        "bad messages": stats.bad_messages,
        "refused values": stats.refused_values,
        "controller errors": stats.controller_errors,
        "curves without result": stats.traces_without_result,
        "results without curves": stats.results_without_traces,
        "curves refused": stats.traces_refused,
        "results given up": stats.results_given_up,
        "new controller epochs": stats.epochs,
        "controller times refused": stats.clock_refused,
    }
    noted = ", ".join(f"{count} {name}" for name, count in faults.items() if count)
    return (
        f"Open Protocol {stats.controller}: {stats.connects} connects, {stats.results} results "
        f"({stats.results_filled} filled by id), {stats.traces} curves"
        + (f"; {noted}" if noted else "")
    )
