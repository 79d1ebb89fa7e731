"""A report's columns straight from the store: :func:`program_columns`.

``boltwatch report`` over a month of a line reads one to two million
tightenings. Made into a :class:`TighteningResult` each (with its steps), a
month of 20 stations took about 26 s; the statistics need only a few
columns per program (:class:`~shared.quality.program_columns.ProgramColumns`),
so they come in a few statements: the figures of every run as one array
(the only statement whose rows grow with the range), and what is counted
(windows, the latest result's name and windows, NOK reasons of the NOK
runs, stop reasons, stations, tools) grouped by the database. The same
columns as :func:`shared.quality.program_columns.columns_of` makes from the
results themselves: one report either way.
"""

from __future__ import annotations

import dataclasses
from collections import Counter, defaultdict
from typing import Any

import numpy as np

from shared.quality.program_columns import (
    JUDGED_FIGURES,
    TOOL_STOPPED,
    ProgramColumns,
    Window,
    reason_kinds,
)
from shared.results.results_query import ResultsQuery
from shared.results.results_store import ResultsStore

#: the columns of each run, in this order: what the figures' arrays are made of
_FIGURE_COLUMNS = (
    "program_id",
    "torque_nm",
    "angle_deg",
    "force_n",
    "process_intensity",
    "events",
    "CASE WHEN result = 'NOK' THEN 1 ELSE 0 END",
)
#: each judged figure's window columns, in the order of JUDGED_FIGURES
_WINDOW_COLUMNS = (
    "torque_min_nm, torque_max_nm",
    "angle_min_deg, angle_max_deg",
    "force_min_n, force_max_n",
)
_WINDOWS = ", ".join(_WINDOW_COLUMNS)


def program_columns(store: ResultsStore, query: ResultsQuery) -> list[ProgramColumns]:
    """The columns of each program of the tightenings ``query`` asks for (its limit and
    order ignored: every one, in the order the runs ended), by program id."""
    everything = dataclasses.replace(query, limit=None, oldest_first=True)
    where, parameters = everything.where()

    def rows(sql: str, where: str = where, parameters: list[Any] = parameters) -> list[Any]:
        return store.database.rows(sql.format(where=where), parameters)

    figures = _figure_array(rows(f"SELECT {', '.join(_FIGURE_COLUMNS)} FROM tightenings{{where}}"
                                 f"{everything.order()}"))  # fmt: skip
    if not len(figures):
        return []
    windows: dict[int, list[set[Window]]] = defaultdict(lambda: [set() for _ in JUDGED_FIGURES])
    for program_id, *bounds in rows(
        f"SELECT program_id, {_WINDOWS} FROM tightenings{{where}} GROUP BY program_id, {_WINDOWS}"
    ):
        for index, seen in enumerate(windows[program_id]):
            seen.add((bounds[2 * index], bounds[2 * index + 1]))
    newest = {
        program_id: (name, bounds)
        for program_id, name, *bounds in rows(
            f"SELECT program_id, program_name, {_WINDOWS} FROM (SELECT program_id, program_name, "
            f"{_WINDOWS}, ROW_NUMBER() OVER (PARTITION BY program_id ORDER BY ended_ns DESC, "
            "station DESC, run_id DESC) AS newest FROM tightenings{where}) AS ranked "
            "WHERE newest = 1"
        )
    }
    nok_reasons: dict[int, Counter[str]] = defaultdict(Counter)
    nok_where, nok_parameters = dataclasses.replace(everything, nok_only=True).where()
    for program_id, reasons in rows(
        "SELECT program_id, nok_reasons FROM tightenings{where}", nok_where, nok_parameters
    ):
        nok_reasons[program_id].update(reason_kinds(reasons))
    stop_reasons: dict[int, Counter[str]] = defaultdict(Counter)
    for program_id, reason, runs in rows(
        "SELECT program_id, stop_reason, COUNT(*) FROM tightenings{where} "
        "GROUP BY program_id, stop_reason"
    ):
        stop_reasons[program_id][reason or TOOL_STOPPED] += int(runs)
    stations, tools = defaultdict(list), defaultdict(list)
    for program_id, station in rows(
        "SELECT DISTINCT program_id, station FROM tightenings{where} ORDER BY station"
    ):
        stations[program_id].append(station)
    for program_id, tool_id in rows(
        "SELECT DISTINCT program_id, tool_id FROM tightenings{where} ORDER BY tool_id"
    ):
        tools[program_id].append(int(tool_id))
    columns = []
    for program_id in sorted(newest):
        of_program = figures[figures[:, 0] == program_id]
        name, bounds = newest[program_id]
        columns.append(
            ProgramColumns(
                program_id=program_id,
                program_name=name,
                runs=len(of_program),
                noks=int(of_program[:, 6].sum()),
                values={
                    key: _measured(of_program[:, 1 + index])
                    for index, key in enumerate((*JUDGED_FIGURES, "intensity"))
                },
                latest_windows={
                    key: (bounds[2 * index], bounds[2 * index + 1])
                    for index, key in enumerate(JUDGED_FIGURES)
                },
                window_counts={
                    key: len(windows[program_id][index]) for index, key in enumerate(JUDGED_FIGURES)
                },
                nok_reasons=nok_reasons[program_id],
                stop_reasons=stop_reasons[program_id],
                events_per_run=[int(events) for events in _measured(of_program[:, 5])],
                stations=stations[program_id],
                tools=tools[program_id],
            )
        )
    return columns


def _figure_array(rows: list[tuple[Any, ...]]) -> np.ndarray:
    """The runs' figures as one float array, a row a run (NaN: not measured)."""
    return np.array(rows, dtype=np.float64).reshape(len(rows), len(_FIGURE_COLUMNS))


def _measured(column: np.ndarray) -> np.ndarray:
    return column[~np.isnan(column)]
