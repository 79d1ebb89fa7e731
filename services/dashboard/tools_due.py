"""The page's "tools due soonest": every tool of the line's wear replies, forecast now.

Each station's recorder answers ``boltwatch/<st>/wear`` with its tools' lines
and beside them each tool's outlook (its pace and the plant's calendar, what
wears it: :mod:`shared.wear.wear_outlook`). A tool is a plant asset: it is
listed once, with the stations whose replies named it, and forecast against
the ``recorder.wear_service_threshold`` of the first of them
(:func:`shared.wear.forecast`), now: due now first, then by forecast date,
then the tools with no date (and why). Each carries the chart the page draws:
its intensity since service at the end of each production day, the threshold,
and the forecast line from now to the date (with its 80 % interval).
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from shared.errors import InputError
from shared.wear import ToolOutlook, forecast
from shared.wear.wear_forecast_table import soonest_first

#: at most this many tools listed
MAX_TOOLS = 12


@dataclass(frozen=True, slots=True)
class ToolSeen:
    """One tool as a station's wear reply said it."""

    station: str
    tool_id: int
    intensity_since_service: float
    runs_since_service: int
    last_service_ns: int | None
    outlook: ToolOutlook | None
    threshold: float | None  # that station's recorder.wear_service_threshold


def tools_seen(station: str, payload: bytes, threshold: float | None) -> list[ToolSeen]:
    """The tools of a ``wear`` reply with their outlooks (none from a recorder before the
    forecast); InputError when it is no wear reply."""
    try:
        body = json.loads(payload)
        outlooks = body.get("outlooks", {})
        return [
            ToolSeen(
                station=station,
                tool_id=int(line["tool_id"]),
                intensity_since_service=float(line["intensity_since_service"]),
                runs_since_service=int(line["runs_since_service"]),
                last_service_ns=line.get("last_service_ns"),
                outlook=_outlook(outlooks.get(str(line["tool_id"]))),
                threshold=threshold,
            )
            for line in body["tools"]
        ]
    except (ValueError, KeyError, TypeError, AttributeError) as err:
        raise InputError(f"not a wear reply ({type(err).__name__}: {err})") from err


def _outlook(fields: dict[str, Any] | None) -> ToolOutlook | None:
    return None if fields is None else ToolOutlook.from_dict(fields)


def tools_due(seen: Iterable[ToolSeen], now_ns: int) -> list[dict[str, Any]]:
    """The line's tools, the soonest due first, each with its forecast and its chart."""
    first: dict[int, ToolSeen] = {}
    stations: dict[int, list[str]] = {}
    for tool in seen:
        first.setdefault(tool.tool_id, tool)
        stations.setdefault(tool.tool_id, []).append(tool.station)
    told = {
        tool.tool_id: forecast(
            tool.tool_id,
            tool.outlook.pace if tool.outlook else None,
            tool.outlook.calendar if tool.outlook else None,
            tool.intensity_since_service,
            tool.threshold,
            now_ns,
        )
        for tool in first.values()
    }
    shown = []
    for prediction in soonest_first(list(told.values()))[:MAX_TOOLS]:
        tool = first[prediction.tool_id]
        causes = tool.outlook.causes if tool.outlook else []
        top = causes[0] if causes else None
        shown.append(
            {
                "tool_id": tool.tool_id,
                "stations": sorted(set(stations[tool.tool_id])),
                "runs_since_service": tool.runs_since_service,
                "forecast": prediction.to_dict(),
                "basis": tool.outlook.pace.basis if tool.outlook else None,
                "wears_it_most": None
                if top is None
                else {
                    "station": top.station,
                    "program_id": top.program_id,
                    "joint": top.joint,
                    "share": top.share,
                },
                "unusual": [
                    f"program {cause.program_id} at {cause.station}: {cause.unusual}"
                    for cause in causes
                    if cause.unusual
                ],
                "chart": _chart(tool, prediction.due_ns, prediction.early_ns, prediction.late_ns,
                                now_ns),
            }
        )  # fmt: skip
    return shown


def _chart(
    tool: ToolSeen, due_ns: int | None, early_ns: int | None, late_ns: int | None, now_ns: int
) -> dict[str, Any]:
    """What the page draws: the intensity since service by production day (and now), the
    threshold, and the forecast line from now to the threshold on the forecast date."""
    points: list[tuple[int, float]] = list(tool.outlook.since_service) if tool.outlook else []
    now = tool.intensity_since_service
    if points:  # summed by day or at once, the last bits of rounding differ: it never falls
        now = max(now, points[-1][1])
        if points[-1][0] < now_ns:
            points.append((now_ns, now))
        now_ns = points[-1][0]  # the forecast goes on from the reply's reading
    return {
        "points": [list(point) for point in points],
        "threshold": tool.threshold,
        "forecast": None
        if due_ns is None or tool.threshold is None
        else [[now_ns, now], [due_ns, tool.threshold]],
        "early_ns": early_ns,
        "late_ns": late_ns,
    }
