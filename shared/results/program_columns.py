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
results themselves: one report either way. A tightening whose figures cannot
be a measurement (:mod:`shared.quality.plausible_result`: a torque of
1e308 Nm) is left out of every statement; :func:`implausible_rows` names them.
"""

from __future__ import annotations

import dataclasses
from collections import Counter, defaultdict
from typing import Any

import numpy as np

from shared.quality import figures_fault, refusal_line
from shared.quality.plausible_result import EVENTS_LIMIT, FIGURE_LIMITS, INTENSITY_LIMIT
from shared.quality.program_columns import (
    JUDGED_FIGURES,
    TOOL_STOPPED,
    ProgramColumns,
    reason_kinds,
)
from shared.results.results_query import ResultsQuery
from shared.results.results_store import ResultsStore

#: what each run gives, in the order the runs ended: the figures' arrays, NOK reasons
_RUN_COLUMNS = (
    "program_id, torque_nm, angle_deg, force_n, process_intensity, events, "
    "CASE WHEN result = 'NOK' THEN nok_reasons END"
)
#: each judged figure's window, in the order of JUDGED_FIGURES
_WINDOWS = "torque_min_nm, torque_max_nm, angle_min_deg, angle_max_deg, force_min_n, force_max_n"
#: what is counted, grouped by the database
_GROUPS = f"program_id, station, tool_id, stop_reason, {_WINDOWS}"
#: each judged figure's value and window, in the order of JUDGED_FIGURES
_JUDGED = (
    ("torque_nm", "torque_min_nm", "torque_max_nm"),
    ("angle_deg", "angle_min_deg", "angle_max_deg"),
    ("force_n", "force_min_n", "force_max_n"),
)
#: a tightening whose figures cannot be a measurement (NULL: not measured, never beyond)
_IMPLAUSIBLE = " OR ".join(
    [
        f"ABS(COALESCE({column}, 0)) > {limit!r}"
        for (_, limit, _), columns in zip(FIGURE_LIMITS, _JUDGED, strict=True)
        for column in columns
    ]
    + [
        f"COALESCE(events, 0) > {EVENTS_LIMIT}",
        "COALESCE(process_intensity, 0) < 0",
        f"COALESCE(process_intensity, 0) > {INTENSITY_LIMIT!r}",
    ]
)


def _and(where: str, condition: str) -> str:
    """``where`` (`` WHERE ...`` or empty) and ``condition``."""
    return f"{where} AND ({condition})" if where else f" WHERE ({condition})"


def implausible_rows(store: ResultsStore, query: ResultsQuery) -> list[str]:
    """A line for each tightening ``query`` asks for whose figures cannot be a measurement
    (left out of :func:`program_columns`), in the order the runs ended."""
    everything = dataclasses.replace(query, limit=None, oldest_first=True)
    where, parameters = everything.where()
    judged = ", ".join(column for columns in _JUDGED for column in columns)
    rows = store.database.rows(
        f"SELECT station, run_id, tool_id, {judged}, events, process_intensity FROM "
        f"tightenings{_and(where, _IMPLAUSIBLE)}{everything.order()}",
        parameters,
    )
    lines = []
    for station, run_id, tool_id, *figures in rows:
        judged_figures = [tuple(figures[index : index + 3]) for index in (0, 3, 6)]
        why = figures_fault(judged_figures, figures[9], figures[10])
        lines.append(refusal_line(station, run_id, tool_id, why or "beyond the bounds"))
    return lines


def program_columns(store: ResultsStore, query: ResultsQuery) -> list[ProgramColumns]:
    """The columns of each program of the tightenings ``query`` asks for (its limit and
    order ignored: every one, in the order the runs ended), by program id."""
    everything = dataclasses.replace(query, limit=None, oldest_first=True)
    where, parameters = everything.where()
    where = _and(where, f"NOT ({_IMPLAUSIBLE})")
    rows = store.database.rows(
        f"SELECT {_RUN_COLUMNS} FROM tightenings{where}{everything.order()}", parameters
    )
    if not rows:
        return []
    figures = np.array([row[:6] for row in rows], dtype=np.float64)  # None: NaN
    nok_reasons: dict[int, list[str]] = defaultdict(list)
    for row in rows:
        if row[6] is not None:
            nok_reasons[row[0]].append(row[6])
    del rows
    grouped: dict[int, list[tuple[Any, ...]]] = defaultdict(list)
    for program_id, *group in store.database.rows(
        f"SELECT {_GROUPS}, COUNT(*) FROM tightenings{where} GROUP BY {_GROUPS}", parameters
    ):
        grouped[program_id].append(tuple(group))
    columns = []
    for program_id in sorted(grouped):
        latest = dataclasses.replace(everything, program_id=program_id, oldest_first=False, limit=1)
        latest_where, latest_parameters = latest.where()  # by the index of program_id
        latest_where = _and(latest_where, f"NOT ({_IMPLAUSIBLE})")
        ((name, *newest),) = store.database.rows(
            f"SELECT program_name, {_WINDOWS} FROM tightenings{latest_where}{latest.order()}",
            latest_parameters,
        )
        of_program = figures[figures[:, 0] == program_id]
        groups = grouped[program_id]
        stop_reasons: Counter[str] = Counter()
        for _station, _tool, reason, *_windows, runs in groups:
            stop_reasons[reason or TOOL_STOPPED] += int(runs)
        reasons: Counter[str] = Counter()
        for text in nok_reasons[program_id]:
            reasons.update(reason_kinds(text))
        columns.append(
            ProgramColumns(
                program_id=program_id,
                program_name=name,
                runs=len(of_program),
                noks=len(nok_reasons[program_id]),
                values={
                    key: _measured(of_program[:, 1 + index])
                    for index, key in enumerate((*JUDGED_FIGURES, "intensity"))
                },
                latest_windows={
                    key: (newest[2 * index], newest[2 * index + 1])
                    for index, key in enumerate(JUDGED_FIGURES)
                },
                window_counts={
                    key: len({group[3 + 2 * index : 5 + 2 * index] for group in groups})
                    for index, key in enumerate(JUDGED_FIGURES)
                },
                nok_reasons=reasons,
                stop_reasons=stop_reasons,
                events_per_run=[int(events) for events in _measured(of_program[:, 5])],
                stations=sorted({group[0] for group in groups}),
                tools=sorted({int(group[1]) for group in groups}),
            )
        )
    return columns


def _measured(column: np.ndarray) -> np.ndarray:
    """The values of the runs that measured it (NaN: not measured)."""
    return column[~np.isnan(column)]
