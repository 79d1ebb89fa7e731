"""The wear ledger as a table for people (``boltwatch wear``).

Beside each tool: its serial, and the dates of its last calibration and
service, when a controller said them (a controller bridge's ToolData: ``-``
otherwise). ``last service`` is the service recorded in boltwatch (``boltwatch
wear service``), from which "since service" counts; ``tool service`` is the
controller's date. ``runs`` are the tool's tightenings; its loosenings (runs
that turned it back) are counted beside them, and their intensity is in
``I_total`` and ``I/run`` (of every run) and since service.
"""

from __future__ import annotations

from datetime import UTC, datetime

from shared.wear.wear_ledger import ToolWear

HEADER = (
    "tool",
    "serial",
    "runs",
    "I_total",
    "I/run",
    "I since service",
    "runs since",
    "loosenings",
    "last service",
    "calibrated",
    "tool service",
    "stations",
    "worst runs",
)


def utc_text(time_ns: int | None) -> str:
    if time_ns is None:
        return "never"
    return f"{datetime.fromtimestamp(time_ns / 1e9, UTC):%Y-%m-%d %H:%M} UTC"


def row(wear: ToolWear) -> tuple[str, ...]:
    worst = ", ".join(
        f"{run.station}/run{run.run_id} {run.process_intensity:.3g}" for run in wear.worst_runs
    )
    service = utc_text(wear.last_service_ns)
    if wear.last_service_note:
        service += f" ({wear.last_service_note})"
    said = wear.controller
    return (
        str(wear.tool_id),
        said.tool_serial if said else "-",
        str(wear.runs),
        f"{wear.total_intensity:.4g}",
        f"{wear.intensity_per_run:.3g}",
        f"{wear.intensity_since_service:.4g}",
        str(wear.runs_since_service),
        str(wear.loosenings),
        service,
        _said_date(said.last_calibration_ns if said else None),
        _said_date(said.last_service_ns if said else None),
        ",".join(wear.stations) or "-",
        worst or "-",
    )


def _said_date(time_ns: int | None) -> str:
    """A date a controller keeps (calibration, service): its day; ``-`` when not said."""
    if time_ns is None:
        return "-"
    return f"{datetime.fromtimestamp(time_ns / 1e9, UTC):%Y-%m-%d}"


#: the columns of numbers, right-aligned
_NUMBERS = frozenset(("runs", "I_total", "I/run", "I since service", "runs since", "loosenings"))


def format_table(tools: list[ToolWear], station: str | None = None) -> str:
    """Aligned text table, one line per tool; says so when the ledger (or station) is empty."""
    if not tools:
        if station is not None:
            return f"the wear ledger has no runs at station {station}"
        return "the wear ledger has no runs yet"
    rows = [HEADER, *(row(tool) for tool in tools)]
    widths = [max(len(r[i]) for r in rows) for i in range(len(HEADER) - 1)]
    lines = []
    for r in rows:
        cells = [
            cell.rjust(width) if HEADER[i] in _NUMBERS or i == 0 else cell.ljust(width)
            for i, (cell, width) in enumerate(zip(r, widths, strict=False))
        ]
        lines.append("  ".join([*cells, r[-1]]))
    return "\n".join(lines)
