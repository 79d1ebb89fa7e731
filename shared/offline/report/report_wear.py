"""The report's "Tool wear": each tool's service forecast and what wears it, as of now.

For the tools of the report's stations in the wear ledger (the first station
file's recordings folder; ``--tool``: that one): the intensity since its
service against the threshold, its forecast (:mod:`shared.wear.wear_forecast`:
the date, its 80 % interval, the runs left, the shift change to plan it at, or
why there is no date), and the share of its wear since its service by
program, station and joint, with the intensity per run of each
(:mod:`shared.wear.wear_outlook`), and what is far above its own history. The
report's time range does not apply: a forecast is made now, from the ledger.
"""

from __future__ import annotations

import html
from dataclasses import dataclass
from datetime import UTC, datetime

from shared.wear import ToolForecast, ToolWear
from shared.wear.wear_forecast_table import soonest_first, unusual_lines


@dataclass(frozen=True, slots=True)
class WearPart:
    """The tools of the report and their forecasts (made at ``made_ns``)."""

    tools: list[ToolWear]
    forecasts: list[ToolForecast]
    threshold: float | None
    ledger: str  # the ledger file read


def _utc(time_ns: int | None) -> str:
    if time_ns is None:
        return "later"
    return f"{datetime.fromtimestamp(time_ns / 1e9, UTC):%Y-%m-%d %H:%M} UTC"


def forecast_text(told: ToolForecast) -> str:
    """The forecast in words."""
    if told.state == "due":
        return "due now (past its service threshold)"
    if told.state != "forecast":
        return f"no date: {told.reason}"
    plan = f"; plan by the shift change {_utc(told.service_by_ns)}" if told.service_by_ns else ""
    return (
        f"due {_utc(told.due_ns)} (80 %: {_utc(told.early_ns)} to {_utc(told.late_ns)}), in "
        f"{told.production_days or 0.0:.1f} production days{plan}"
    )


def _shares(tool: ToolWear) -> list[tuple[str, str, float, float]]:
    if tool.outlook is None:
        return []
    return [
        (by, name, share, per_run)
        for by in ("program", "station", "joint")
        for name, share, per_run in tool.outlook.shares(by)
    ]


def wear_html(part: WearPart) -> str:
    """The section of the page."""
    by_id = {tool.tool_id: tool for tool in part.tools}
    threshold = "not set" if part.threshold is None else f"{part.threshold:.4g}"
    blocks = [
        "<h2>Tool wear</h2>",
        f"<p>from the wear ledger {html.escape(part.ledger)}, as of now; service threshold "
        f"{threshold}</p>",
    ]
    for told in soonest_first(part.forecasts):
        tool = by_id[told.tool_id]
        runs = "–" if told.runs_left is None else str(told.runs_left)
        rows = "".join(
            f"<tr><td class=name>{html.escape(by)}</td><td class=name>{html.escape(name)}</td>"
            f"<td>{100 * share:.1f} %</td><td>{per_run:.4g}</td></tr>"
            for by, name, share, per_run in _shares(tool)
        )
        blocks.append(
            f"<h3>Tool {tool.tool_id}</h3><p>intensity since service "
            f"{tool.intensity_since_service:.4g} ({tool.runs_since_service} runs); "
            f"{html.escape(forecast_text(told))}; runs left {runs}</p>"
            "<table><tr><th>by</th><th>name</th><th>share since service</th>"
            f"<th>intensity per run</th></tr>{rows}</table>"
        )
    notes = unusual_lines(part.tools)
    if notes:
        items = "".join(f"<li>{html.escape(line)}</li>" for line in notes)
        blocks.append(f"<p>far above their own history:</p><ul>{items}</ul>")
    return "".join(blocks)


def wear_lines(part: WearPart) -> list[str]:
    """The lines printed on the terminal: one per tool, then what is unusual."""
    by_id = {tool.tool_id: tool for tool in part.tools}
    lines = []
    for told in soonest_first(part.forecasts):
        tool = by_id[told.tool_id]
        top = tool.outlook.shares("program")[:2] if tool.outlook else []
        most = ", ".join(f"{name} {100 * share:.0f} %" for name, share, _ in top)
        lines.append(
            f"tool {tool.tool_id}: {forecast_text(told)}; runs left "
            f"{'-' if told.runs_left is None else told.runs_left}"
            + (f"; wear since service: {most}" if most else "")
        )
    return [*lines, *unusual_lines(part.tools)]
