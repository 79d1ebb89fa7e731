"""Stored tightenings for people and programs: a table, CSV, JSON (``boltwatch results``).

The table has one line per tightening, newest first (the station by its id,
its name for people beside it; a part restored from the line when the
predictor started, not scanned before the run, marked so), its last column
the recording (``boltwatch inspect <it> --run <run>`` draws the run); CSV has
every column of the store, JSON every field with the steps. A multi-spindle
station's tightening says its spindle and its cycle (sync id and the cycle's
common result): in the table two columns after the run (only when a row has a
spindle: a single-spindle station's table is as it was), in CSV the last three,
in JSON its ``spindle``, ``sync_id`` and ``cycle`` (the common result, when
stored).
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Sequence
from datetime import UTC, datetime
from typing import Any

from shared.contract import JudgedFigure, to_dict
from shared.results.stored_result import StoredResult

HEADER = (
    "ended (UTC)", "station", "plant", "line", "run", "part", "program", "tool", "result",
    "torque Nm", "angle deg", "preload kN", "stopped on", "events", "why NOK", "recording",
)  # fmt: skip
CSV_HEADER = (
    "ended_utc", "station", "station_name", "plant", "line", "run_id", "tightening_id",
    "part_id", "part_source", "program_id", "program_name", "tool_id", "batch_counter",
    "result", "nok_reasons",
    "torque_nm", "torque_min_nm", "torque_max_nm", "torque_status",
    "angle_deg", "angle_min_deg", "angle_max_deg", "angle_status",
    "force_n", "force_min_n", "force_max_n", "force_status",
    "stop_reason", "events", "process_intensity", "source", "recording", "recording_host",
    "pulses", "spindle", "sync_id", "cycle_result",
)  # fmt: skip
#: the columns a multi-spindle station's rows add to the table, after the run
SPINDLE_HEADER = ("spindle", "cycle")


def utc_text(time_ns: int) -> str:
    return f"{datetime.fromtimestamp(time_ns / 1e9, UTC):%Y-%m-%d %H:%M:%S}"


def _figure(figure: JudgedFigure, scale: float = 1.0) -> str:
    if figure.value is None:
        return "-"
    mark = "" if figure.status in ("ok", "not_judged") else f" ({figure.status})"
    return f"{figure.value / scale:.4g}{mark}"


def _part(part_id: str | None, source: str | None) -> str:
    """The part, marked when it was not scanned before the run (restored from the line when
    the predictor started: it may be stale)."""
    if part_id is None:
        return "-"
    return f"{part_id} ({source})" if source == "restored" else part_id


def _stopped_on(reason: str | None, pulses: int | None) -> str:
    """What stopped the tool, and a final stage's pulses after it (``target_reached+pulse``)."""
    text = reason or "-"
    if pulses:
        text += "+pulse" if pulses == 1 else f"+{pulses}pulses"
    return text


def _cycle(stored: StoredResult) -> str:
    """The cycle a spindle's run is of: its sync id, and its common result when stored."""
    r = stored.result
    if r.sync_id is None:
        return "-"
    cycle = stored.cycle
    return f"{r.sync_id}" if cycle is None else f"{r.sync_id} {cycle.result}"


def row(stored: StoredResult, spindles: bool = False) -> tuple[str, ...]:
    """The table's cells of one tightening (``spindles``: with the spindle's columns)."""
    cells = _cells(stored)
    if not spindles:
        return cells
    spindle = stored.result.spindle
    at = HEADER.index("run") + 1
    return (*cells[:at], "-" if spindle is None else str(spindle), _cycle(stored), *cells[at:])


def _cells(stored: StoredResult) -> tuple[str, ...]:
    r = stored.result
    return (
        utc_text(r.time_ns),
        f"{r.station} ({stored.station_name})" if stored.station_name else r.station,
        stored.plant or "-",
        stored.line or "-",
        str(r.run_id),
        _part(r.part_id, r.part_source),
        f"{r.program_id} {r.program_name}".strip(),
        str(r.tool_id),
        r.result,
        _figure(r.final_torque_nm),
        _figure(r.final_angle_deg),
        _figure(r.final_force_n, 1000.0),
        _stopped_on(r.stop_reason, r.pulses),
        "-" if r.events is None else str(r.events),
        r.nok_reasons or "-",
        stored.recording or "-",
    )


def format_table(results: Sequence[StoredResult]) -> str:
    spindles = any(stored.result.spindle is not None for stored in results)
    header: tuple[str, ...] = HEADER
    if spindles:
        at = HEADER.index("run") + 1
        header = (*HEADER[:at], *SPINDLE_HEADER, *HEADER[at:])
    rows = [header, *(row(stored, spindles) for stored in results)]
    widths = [max(len(cells[i]) for cells in rows) for i in range(len(header))]
    return "\n".join(
        "  ".join(cell.ljust(width) for cell, width in zip(cells, widths, strict=True)).rstrip()
        for cells in rows
    )


def csv_row(stored: StoredResult) -> list[Any]:
    r = stored.result
    figures: list[Any] = []
    for figure in (r.final_torque_nm, r.final_angle_deg, r.final_force_n):
        figures += [figure.value, figure.min, figure.max, figure.status]
    return [
        utc_text(r.time_ns), r.station, stored.station_name, stored.plant, stored.line,
        r.run_id, r.tightening_id, r.part_id, r.part_source, r.program_id, r.program_name,
        r.tool_id,
        r.batch_counter, r.result, r.nok_reasons,
        *figures, r.stop_reason, r.events, r.process_intensity, r.source, stored.recording,
        stored.recording_host, r.pulses, r.spindle, r.sync_id,
        None if stored.cycle is None else stored.cycle.result,
    ]  # fmt: skip


def format_csv(results: Sequence[StoredResult]) -> str:
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(CSV_HEADER)
    writer.writerows(csv_row(stored) for stored in results)
    return out.getvalue()


def as_dict(stored: StoredResult) -> dict[str, Any]:
    """A tightening as JSON: the TighteningResult's fields, where it was tightened (the
    station's name, plant and line), its recording and, a spindle's run of a multi-spindle
    cycle, its cycle's common result."""
    document = to_dict(stored.result)
    document["ended_utc"] = utc_text(stored.result.time_ns)
    document["station_name"] = stored.station_name
    document["plant"] = stored.plant
    document["line"] = stored.line
    document["recording"] = stored.recording
    document["recording_host"] = stored.recording_host
    cycle = stored.cycle
    if cycle is not None:  # a multi-spindle cycle's run: the cycle's common result
        document["cycle"] = {
            "sync_id": cycle.sync_id,
            "spindles": cycle.spindles,
            "result": cycle.result,
            "nok_reasons": cycle.nok_reasons,
            "ended_utc": utc_text(cycle.ended_ns),
        }
    return document


def format_json(results: Sequence[StoredResult]) -> str:
    return json.dumps([as_dict(stored) for stored in results], indent=1)
