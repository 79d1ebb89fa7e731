"""The plant's wear: the ``boltwatch/<st>/wear`` replies of every line's recorder, merged.

A plant has one recorder, and so one wear ledger, per line; a tool is a plant
asset and may have run on several lines. ``boltwatch wear --plant`` asks
``boltwatch/*/wear`` and gets one reply per station: each holds the lines of
the tools that ran at that station, with the whole totals of the ledger that
answered (``host`` and ``ledger`` say which). Merging:

- replies of the same ledger carry the same tool lines (several stations of
  one line): each tool is taken once per ledger (the one with the most runs,
  should a run have been added between two replies);
- across ledgers a tool's figures add up: runs (and loosenings), ``I_total`` (eq. 69: a sum
  over runs, and each run is in exactly one ledger: runs are keyed by station,
  and a station belongs to one line), the runs and intensity since service;
  its worst runs are the worst of all; its stations the union; its last
  service the latest any ledger holds; what its controller said of it (serial,
  calibration) the newest any ledger received; its outlook (pace, causes of
  wear: what its forecast is made of) none, since each ledger measured only
  its own part of the tool's days: ``boltwatch wear`` on each line forecasts it.

What a merge cannot make exact: a service is recorded in one ledger
(``boltwatch wear service`` on that line); another line's ledger that has runs
of the same tool does not know it, and counts its runs since its own last
service (or all of them). The merged "since service" figures are then too
high, never too low: a tool is flagged early, not late.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from shared.errors import InputError
from shared.wear.wear_ledger import WORST_RUNS, RunWear, ToolWear
from shared.wear.wear_outlook import ToolOutlook
from shared.wear.wear_tool_data import ControllerTool


@dataclass(frozen=True, slots=True)
class WearReply:
    """One recorder's answer for one station."""

    station: str
    ledger: str  # "<host>:<path>": which ledger answered
    tools: list[ToolWear]


def parse_reply(payload: bytes) -> WearReply:
    """A ``boltwatch/<st>/wear`` reply; InputError naming what is wrong."""
    try:
        body = json.loads(payload)
        # each tool's outlook beside the tool lines (which a plant's older boltwatch reads as
        # they were); none in a reply of a recorder before the forecast
        outlooks = body.get("outlooks", {})
        tools = [_tool(line, outlooks.get(str(line["tool_id"]))) for line in body["tools"]]
        host = str(body.get("host", ""))
        return WearReply(str(body["station"]), f"{host}:{body['ledger']}", tools)
    except (ValueError, KeyError, TypeError) as err:
        raise InputError(f"not a wear reply ({type(err).__name__}: {err})") from err


def _tool(line: dict[str, Any], outlook: dict[str, Any] | None) -> ToolWear:
    fields = dict(line)
    fields["worst_runs"] = [RunWear(**run) for run in line["worst_runs"]]
    fields["stations"] = list(line["stations"])
    controller = line.get("controller")  # absent in a reply of a ledger before tool data
    fields["controller"] = None if controller is None else ControllerTool.from_dict(controller)
    fields["outlook"] = None if outlook is None else ToolOutlook.from_dict(outlook)
    return ToolWear(**fields)


def merge(replies: Iterable[WearReply], station: str | None = None) -> list[ToolWear]:
    """The plant's line per tool, by id (only tools that ran at ``station``, whole totals)."""
    per_ledger: dict[str, dict[int, ToolWear]] = {}
    for reply in replies:
        tools = per_ledger.setdefault(reply.ledger, {})
        for tool in reply.tools:
            kept = tools.get(tool.tool_id)
            if kept is None or tool.runs + tool.loosenings > kept.runs + kept.loosenings:
                tools[tool.tool_id] = tool
    by_tool: dict[int, list[ToolWear]] = {}
    for tools in per_ledger.values():
        for tool in tools.values():
            by_tool.setdefault(tool.tool_id, []).append(tool)
    merged = [_merged(parts) for _, parts in sorted(by_tool.items())]
    if station is not None:
        merged = [tool for tool in merged if station in tool.stations]
    return merged


def _merged(parts: list[ToolWear]) -> ToolWear:
    if len(parts) == 1:
        return parts[0]
    runs = sum(part.runs for part in parts)
    loosenings = sum(part.loosenings for part in parts)
    total = sum(part.total_intensity for part in parts)
    serviced = [part for part in parts if part.last_service_ns is not None]
    latest = max(serviced, key=lambda part: part.last_service_ns or 0) if serviced else None
    said = [part.controller for part in parts if part.controller is not None]
    worst = sorted(
        (run for part in parts for run in part.worst_runs),
        key=lambda run: (-run.process_intensity, run.ended_ns),
    )[:WORST_RUNS]
    return ToolWear(
        tool_id=parts[0].tool_id,
        runs=runs,
        total_intensity=total,
        intensity_per_run=total / (runs + loosenings) if runs + loosenings else 0.0,
        last_service_ns=latest.last_service_ns if latest else None,
        last_service_note=latest.last_service_note if latest else None,
        runs_since_service=sum(part.runs_since_service for part in parts),
        intensity_since_service=sum(part.intensity_since_service for part in parts),
        worst_runs=worst,
        stations=sorted({name for part in parts for name in part.stations}),
        controller=max(said, key=lambda tool: tool.received_ns) if said else None,
        loosenings=loosenings,
        outlook=None,
    )
