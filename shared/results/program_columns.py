"""A report's columns straight from the store: :func:`program_columns`.

``boltwatch report`` over a month of a line reads one to two million
tightenings. Made into a :class:`TighteningResult` each (with its steps), a
month of 20 stations took about 26 s; the statistics need only a few
columns per program (:class:`~shared.quality.program_columns.ProgramColumns`),
so they come in one scan of the range, in the order the runs ended: each
run's figures (made one array), its NOK reasons, and what is counted (the
station, the tool, the stop reason, the windows), counted here. Grouping in
the database took a second scan: SQLite read it through the station index,
a second slower than the first (2.7 s against 1.6 s for a month of 20
stations in 10 million results), and counting the scan's rows takes 0.4 s.
The latest result's name and windows of each program are read by its index.
The same columns as :func:`shared.quality.program_columns.columns_of` makes
from the results themselves: one report either way. A tightening whose
figures cannot be a measurement (:mod:`shared.quality.plausible_result`: a
torque of 1e308 Nm) is no result in the store (:mod:`.refused_results`): it is
named (:attr:`StoredColumns.refused`), in the words the report uses for it
read from its file, and never counted. A multi-spindle station's program has,
after its columns, each spindle's (counted by spindle in the same scan).
"""

from __future__ import annotations

import dataclasses
from collections import Counter, defaultdict
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from shared.quality.program_columns import (
    JUDGED_FIGURES,
    TOOL_STOPPED,
    ProgramColumns,
    reason_kinds,
)
from shared.results.refused_results import JUDGED_COLUMNS
from shared.results.results_query import ResultsQuery
from shared.results.results_store import ResultsStore

_WINDOWS = ", ".join(column for _value, *window in JUDGED_COLUMNS for column in window)
#: what is counted: of each program (and spindle: NULL, a single-spindle station's), its runs
#: by station, tool, stop reason, a final stage's pulses (NULL: no final stage) and windows
_GROUPS = f"program_id, spindle, station, tool_id, stop_reason, pulses, {_WINDOWS}"
#: what each run gives, in the order the runs ended: the figures' arrays, NOK reasons, and
#: what it is counted by
_RUN_COLUMNS = (
    "program_id, spindle, torque_nm, angle_deg, force_n, process_intensity, events, "
    "CASE WHEN result = 'NOK' THEN nok_reasons END, " + _GROUPS
)
#: where the columns of _GROUPS start in a row of _RUN_COLUMNS
_GROUP_AT = 8
#: a single-spindle station's runs in the array of spindles
_NO_SPINDLE = -1
#: rows of the scan made into Python at once (a month of a line is a million and more: as
#: one list of tuples, 464 bytes a row)
_BATCH_ROWS = 50_000


@dataclass
class StoredColumns:
    """What :func:`program_columns` read: each program's columns, and a line for each
    tightening kept aside because its figures cannot be a measurement."""

    programs: list[ProgramColumns] = field(default_factory=list)
    refused: list[str] = field(default_factory=list)


def program_columns(store: ResultsStore, query: ResultsQuery) -> StoredColumns:
    """The columns of each program of the tightenings ``query`` asks for (its limit and
    order ignored: every one, in the order the runs ended), by program id, and those it
    asks for whose figures cannot be a measurement, named."""
    everything = dataclasses.replace(query, limit=None, oldest_first=True)
    where, parameters = everything.where()
    arrays: list[np.ndarray] = []
    ids: list[np.ndarray] = []  # each run's program id, as it is (a float holds 53 bits)
    spindle_ids: list[np.ndarray] = []  # each run's spindle (_NO_SPINDLE: none)
    nok_reasons: dict[tuple[int, int | None], list[str]] = defaultdict(list)
    counted: Counter[tuple[Any, ...]] = Counter()
    for batch in store.database.row_batches(
        f"SELECT {_RUN_COLUMNS} FROM tightenings{where}{everything.order()}",
        parameters,
        _BATCH_ROWS,
    ):
        ids.append(np.array([row[0] for row in batch], dtype=np.int64))
        spindle_ids.append(
            np.array([_NO_SPINDLE if row[1] is None else row[1] for row in batch], np.int64)
        )
        arrays.append(np.array([row[2:7] for row in batch], dtype=np.float64).reshape(-1, 5))
        for row in batch:
            if row[7] is not None:
                nok_reasons[(row[0], row[1])].append(row[7])
        counted.update(row[_GROUP_AT:] for row in batch)
    figures = np.concatenate(arrays) if arrays else np.empty((0, 5))
    program_ids = np.concatenate(ids) if ids else np.empty(0, dtype=np.int64)
    spindles = np.concatenate(spindle_ids) if spindle_ids else np.empty(0, dtype=np.int64)
    read = StoredColumns(refused=store.refused(everything))
    grouped: dict[int, list[tuple[Any, ...]]] = defaultdict(list)
    for (program_id, *group), runs in counted.items():
        grouped[program_id].append((*group, runs))
    for program_id in sorted(grouped):
        groups = grouped[program_id]
        of_program = program_ids == program_id
        reasons = [
            text for (p, _), texts in nok_reasons.items() if p == program_id for text in texts
        ]
        read.programs.append(
            _columns(store, everything, program_id, None, figures[of_program], groups, reasons)
        )
        for spindle in sorted({group[0] for group in groups if group[0] is not None}):
            read.programs.append(
                _columns(
                    store,
                    everything,
                    program_id,
                    spindle,
                    figures[of_program & (spindles == spindle)],
                    [group for group in groups if group[0] == spindle],
                    nok_reasons[(program_id, spindle)],
                )
            )
    return read


def _columns(
    store: ResultsStore,
    query: ResultsQuery,
    program_id: int,
    spindle: int | None,
    figures: np.ndarray,
    groups: list[tuple[Any, ...]],
    nok_texts: list[str],
) -> ProgramColumns:
    """The columns of one program (``spindle``: of that spindle's runs only) from its runs'
    ``figures``, its counted ``groups`` (spindle, station, tool, stop reason, pulses,
    windows, runs) and the NOK reasons of its NOK runs."""
    name, newest = _latest(store, query, program_id, spindle)
    stop_reasons: Counter[str] = Counter()
    staged = pulsed = 0
    for _spindle, _station, _tool, reason, pulses, *_windows, runs in groups:
        stop_reasons[reason or TOOL_STOPPED] += runs
        staged += runs if pulses is not None else 0
        pulsed += runs if pulses else 0
    reasons: Counter[str] = Counter()
    for text in nok_texts:
        reasons.update(reason_kinds(text))
    return ProgramColumns(
        program_id=program_id,
        program_name=name,
        runs=len(figures),
        noks=len(nok_texts),
        values={
            key: _measured(figures[:, index])
            for index, key in enumerate((*JUDGED_FIGURES, "intensity"))
        },
        latest_windows={
            key: (newest[2 * index], newest[2 * index + 1])
            for index, key in enumerate(JUDGED_FIGURES)
        },
        window_counts={
            key: len({group[5 + 2 * index : 7 + 2 * index] for group in groups})
            for index, key in enumerate(JUDGED_FIGURES)
        },
        nok_reasons=reasons,
        stop_reasons=stop_reasons,
        staged_runs=staged,
        pulsed_runs=pulsed,
        events_per_run=[int(events) for events in _measured(figures[:, 4])],
        stations=sorted({group[1] for group in groups}),
        tools=sorted({int(group[2]) for group in groups}),
        spindle=spindle,
    )


def _latest(
    store: ResultsStore, query: ResultsQuery, program_id: int, spindle: int | None
) -> tuple[str, list[Any]]:
    """The name and windows of ``program_id``'s (``spindle``'s) newest tightening ``query``
    asks for (by the index of program_id)."""
    latest = dataclasses.replace(
        query, program_id=program_id, spindle=spindle, oldest_first=False, limit=1
    )
    where, parameters = latest.where()
    ((name, *windows),) = store.database.rows(
        f"SELECT program_name, {_WINDOWS} FROM tightenings{where}{latest.order()}", parameters
    )
    return name, windows


def _measured(column: np.ndarray) -> np.ndarray:
    """The values of the runs that measured it (NaN: not measured)."""
    return column[~np.isnan(column)]
