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
1e308 Nm) is found in the first statement's scan, named
(:attr:`StoredColumns.refused`) and left out of every statement.
"""

from __future__ import annotations

import dataclasses
from collections import Counter, defaultdict
from dataclasses import dataclass, field
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


def _refusal_lines(store: ResultsStore, keys: list[tuple[str, int]]) -> list[str]:
    """A line for each tightening of ``keys`` (station, run id) saying why its figures
    cannot be a measurement, each read by the table's key."""
    judged = ", ".join(column for columns in _JUDGED for column in columns)
    lines = []
    for key in keys:
        for tool_id, *figures in store.database.rows(
            f"SELECT tool_id, {judged}, events, process_intensity FROM tightenings "
            "WHERE station = ? AND run_id = ?",
            key,
        ):
            judged_figures = [tuple(figures[index : index + 3]) for index in (0, 3, 6)]
            why = figures_fault(judged_figures, figures[9], figures[10])
            lines.append(refusal_line(key[0], key[1], tool_id, why or "beyond the bounds"))
    return lines


@dataclass
class StoredColumns:
    """What :func:`program_columns` read: each program's columns, and a line for each
    tightening left out because its figures cannot be a measurement."""

    programs: list[ProgramColumns] = field(default_factory=list)
    refused: list[str] = field(default_factory=list)


def program_columns(store: ResultsStore, query: ResultsQuery) -> StoredColumns:
    """The columns of each program of the tightenings ``query`` asks for (its limit and
    order ignored: every one, in the order the runs ended), by program id; those whose
    figures cannot be a measurement are found in the same scan, left out and named."""
    everything = dataclasses.replace(query, limit=None, oldest_first=True)
    where, parameters = everything.where()
    rows = store.database.rows(
        f"SELECT {_RUN_COLUMNS}, CASE WHEN ({_IMPLAUSIBLE}) THEN station END, "
        f"CASE WHEN ({_IMPLAUSIBLE}) THEN run_id END FROM tightenings{where}"
        f"{everything.order()}",
        parameters,
    )
    refused = [(row[7], row[8]) for row in rows if row[7] is not None]
    if refused:
        rows = [row for row in rows if row[7] is None]
    read = StoredColumns(refused=_refusal_lines(store, refused))
    if not rows:
        return read
    figures = np.array([row[:6] for row in rows], dtype=np.float64)  # None: NaN
    nok_reasons: dict[int, list[str]] = defaultdict(list)
    for row in rows:
        if row[6] is not None:
            nok_reasons[row[0]].append(row[6])
    del rows
    where = _and(where, f"NOT ({_IMPLAUSIBLE})")
    grouped: dict[int, list[tuple[Any, ...]]] = defaultdict(list)
    for program_id, *group in store.database.rows(
        f"SELECT {_GROUPS}, COUNT(*) FROM tightenings{where} GROUP BY {_GROUPS}", parameters
    ):
        grouped[program_id].append(tuple(group))
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
        read.programs.append(
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
    return read


def _measured(column: np.ndarray) -> np.ndarray:
    """The values of the runs that measured it (NaN: not measured)."""
    return column[~np.isnan(column)]
