"""The tools' service forecasts as a table for people, and as JSON (``boltwatch wear``).

One line per tool, the soonest due first: when it is due (a tool past its
threshold: ``due now``), the 80 % interval of that date, the production days
and tightenings left (with their intervals), the shift change to plan the
service at (the last one before the interval's early end), what wears it
most (the program and station with the largest share of its wear since its
service) and, for a tool with no date, why not. Below the table, the runs and
programs far above their own history (:mod:`.wear_outlook`).
"""

from __future__ import annotations

from datetime import UTC, datetime
from typing import Any

from shared.wear.wear_forecast import ToolForecast, forecast
from shared.wear.wear_ledger import ToolWear

HEADER = (
    "tool",
    "due",
    "80 % between",
    "prod. days",
    "runs left",
    "plan by",
    "wears it most",
    "",
)


def tool_forecasts(
    tools: list[ToolWear], threshold: float | None, now_ns: int
) -> list[ToolForecast]:
    """Each tool's forecast now against ``threshold`` (its outlook's pace and calendar)."""
    return [
        forecast(
            tool.tool_id,
            tool.outlook.pace if tool.outlook is not None else None,
            tool.outlook.calendar if tool.outlook is not None else None,
            tool.intensity_since_service,
            threshold,
            now_ns,
        )
        for tool in tools
    ]


def soonest_first(forecasts: list[ToolForecast]) -> list[ToolForecast]:
    """Due now first, then by forecast date, then those with no date (by tool)."""
    order = {"due": 0, "forecast": 1, "none": 2}
    return sorted(
        forecasts,
        key=lambda told: (order[told.state], told.due_ns or 0, told.tool_id),
    )


def _when(time_ns: int | None) -> str:
    if time_ns is None:
        return "-"
    return f"{datetime.fromtimestamp(time_ns / 1e9, UTC):%Y-%m-%d %H:%M}"


def _day(time_ns: int | None) -> str:
    if time_ns is None:
        return "later"
    return f"{datetime.fromtimestamp(time_ns / 1e9, UTC):%m-%d %H:%M}"


def _range(low: float | int | None, middle: float | int | None, high: float | int | None) -> str:
    if middle is None:
        return "-"
    shown = f"{middle:.1f}" if isinstance(middle, float) else str(middle)
    if low is None and high is None:
        return shown
    low_text = "-" if low is None else (f"{low:.1f}" if isinstance(low, float) else str(low))
    high_text = "…" if high is None else (f"{high:.1f}" if isinstance(high, float) else str(high))
    return f"{shown} ({low_text}–{high_text})"


def most_wear(tool: ToolWear) -> str:
    """The station's program with the largest share of the tool's wear since its service."""
    if tool.outlook is None or not tool.outlook.causes:
        return "-"
    top = tool.outlook.causes[0]
    joint = f", {top.joint}" if top.joint else ""
    return f"program {top.program_id} at {top.station}{joint}: {100 * top.share:.0f} %"


def row(tool: ToolWear, told: ToolForecast) -> tuple[str, ...]:
    if told.state == "due":
        due, between = "due now", "-"
    elif told.state == "forecast":
        due, between = _when(told.due_ns), f"{_day(told.early_ns)} – {_day(told.late_ns)}"
    else:
        due, between = "-", "-"
    days = _range(told.production_days_early, told.production_days, told.production_days_late)
    runs = _range(told.runs_left_low, told.runs_left, told.runs_left_high)
    note = told.reason if told.state == "none" else ""
    if told.state == "forecast" and tool.outlook is not None and tool.outlook.pace.basis:
        note = f"pace of {tool.outlook.pace.basis}"
    return (
        str(tool.tool_id),
        due,
        between,
        days,
        runs,
        _when(told.service_by_ns),
        most_wear(tool),
        note or "",
    )


def format_forecasts(tools: list[ToolWear], forecasts: list[ToolForecast]) -> str:
    """The forecast table (UTC), then what is unusual; "" when there is no tool."""
    if not tools:
        return ""
    by_id = {tool.tool_id: tool for tool in tools}
    rows = [HEADER, *(row(by_id[told.tool_id], told) for told in soonest_first(forecasts))]
    widths = [max(len(r[i]) for r in rows) for i in range(len(HEADER) - 1)]
    threshold = forecasts[0].threshold
    lines = [
        "service forecast (UTC), threshold "
        + ("not set" if threshold is None else f"{threshold:.4g}")
    ]
    for r in rows:
        cells = [cell.ljust(width) for cell, width in zip(r, widths, strict=False)]
        lines.append("  ".join([*cells, r[-1]]).rstrip())
    lines.extend(unusual_lines(tools))
    return "\n".join(lines)


def unusual_lines(tools: list[ToolWear]) -> list[str]:
    """One line per program or run far above its own history."""
    lines = []
    for tool in tools:
        if tool.outlook is None:
            continue
        for cause in tool.outlook.causes:
            if cause.unusual:
                lines.append(
                    f"tool {tool.tool_id}: program {cause.program_id} at {cause.station}: "
                    f"{cause.unusual}"
                )
        for run in tool.outlook.unusual_runs:
            lines.append(
                f"tool {tool.tool_id}: run {run.station}/run{run.run_id} (program "
                f"{run.program_id}, {_when(run.ended_ns)}): intensity {run.process_intensity:.3g}, "
                f"{run.ratio:.1f}× its program's history per run"
            )
    return lines


def forecast_json(tool: ToolWear, told: ToolForecast) -> dict[str, Any]:
    """A tool's line of ``boltwatch wear --json``: the ledger's figures, its outlook, its
    forecast and the share of its wear since its service by program, station and joint."""
    line = tool.to_dict()
    line["forecast"] = told.to_dict()
    line["wear_by"] = {
        by: [
            {"name": name, "share": share, "per_run": per_run}
            for name, share, per_run in (tool.outlook.shares(by) if tool.outlook else [])
        ]
        for by in ("program", "station", "joint")
    }
    return line
