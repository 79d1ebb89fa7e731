"""What a program's statistics are made from, as columns: :class:`ProgramColumns`.

A month of a 20-station line is one to two million results. The report
needs of them only a few columns per program: the measured figures in the
order the runs ended, the windows they were judged against, counts of
verdicts, NOK reasons, stop reasons, events, stations and tools. As columns
they come from the results store in a handful of statements
(:mod:`shared.results.program_columns`), never a Python object per result;
from results read one by one (the recordings), :func:`columns_of` makes the
same columns, so both sources give the same statistics
(:mod:`.program_statistics`). A program a multi-spindle station ran has its
columns over every run, then each spindle's own (``spindle``): a spindle that
drifts shows in its own chart and Cpk.
"""

from __future__ import annotations

import dataclasses
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from shared.contract import JudgedFigure, RunSummary, TighteningResult

#: the figures of a report with a window (judged), and the one without
JUDGED_FIGURES = ("torque", "angle", "preload")
FIGURE_KEYS = (*JUDGED_FIGURES, "intensity")
#: the stop reason shown for a run the tool stopped by itself (no StopCommand)
TOOL_STOPPED = "tool"

Window = tuple[float | None, float | None]


@dataclass
class ProgramColumns:
    """One program's results as columns (every list and array in the order the runs ended)."""

    program_id: int
    program_name: str  # the latest result's
    runs: int
    noks: int
    #: figure key -> the values of the runs that measured it (no NaN)
    values: dict[str, np.ndarray]
    #: judged figure key -> the window of the latest result
    latest_windows: dict[str, Window]
    #: judged figure key -> how many different windows the results were judged against
    window_counts: dict[str, int]
    #: NOK reason kind (``preload low``) -> NOK runs that gave it
    nok_reasons: Counter[str]
    #: stop reason (:data:`TOOL_STOPPED`: the tool stopped by itself) -> runs
    stop_reasons: Counter[str]
    #: stick-slip events of each run that counted them
    events_per_run: list[int]
    stations: list[str]
    tools: list[int]
    #: runs that ran a final stage, and of them the ones that needed a pulse back to the target
    staged_runs: int = 0
    pulsed_runs: int = 0
    #: one spindle's runs of a multi-spindle station; None: every run of the program
    spindle: int | None = None


def reason_kinds(reasons: str) -> set[str]:
    """What each of a run's ``"; "``-separated NOK reasons says without its figures:
    ``preload low: 52800 N, window 53000 to 59000 N`` -> ``preload low`` (a Pareto counts
    kinds, not values; each kind once per run)."""
    return {reason.split(":", 1)[0].strip() for reason in reasons.split(";")} - {""}


def _judged(result: TighteningResult) -> tuple[JudgedFigure, JudgedFigure, JudgedFigure]:
    return result.final_torque_nm, result.final_angle_deg, result.final_force_n


def columns_of(
    results: Sequence[TighteningResult],
    summaries: Mapping[tuple[str, int, int], RunSummary] | None = None,
) -> list[ProgramColumns]:
    """The columns of each program of ``results`` (in the order the runs ended), by program
    id, each followed by its spindles' own (a multi-spindle station's: by spindle number); a
    result without events takes its run's summary's (``summaries`` by station, run id and
    tool id), as recordings hold them."""
    by_program: dict[int, list[TighteningResult]] = {}
    for result in results:
        by_program.setdefault(result.program_id, []).append(result)
    columns = []
    for program_id, runs in sorted(by_program.items()):
        columns.append(_program_columns(program_id, runs, summaries or {}))
        for spindle in sorted({run.spindle for run in runs if run.spindle is not None}):
            of_spindle = [run for run in runs if run.spindle == spindle]
            spindle_columns = _program_columns(program_id, of_spindle, summaries or {})
            columns.append(dataclasses.replace(spindle_columns, spindle=spindle))
    return columns


def _program_columns(
    program_id: int,
    runs: list[TighteningResult],
    summaries: Mapping[tuple[str, int, int], RunSummary],
) -> ProgramColumns:
    judged = [_judged(run) for run in runs]
    values: dict[str, np.ndarray] = {}
    latest_windows: dict[str, Window] = {}
    window_counts: dict[str, int] = {}
    for index, key in enumerate(JUDGED_FIGURES):
        figures = [figures[index] for figures in judged]
        measured = [figure.value for figure in figures if figure.value is not None]
        values[key] = np.asarray(measured, dtype=np.float64)
        latest_windows[key] = (figures[-1].min, figures[-1].max)
        window_counts[key] = len({(figure.min, figure.max) for figure in figures})
    intensity = [run.process_intensity for run in runs if run.process_intensity is not None]
    values["intensity"] = np.asarray(intensity, dtype=np.float64)
    nok_reasons: Counter[str] = Counter()
    for run in runs:
        if run.result == "NOK":
            nok_reasons.update(reason_kinds(run.nok_reasons))
    events = []
    for run in runs:
        summary = summaries.get((run.station, run.run_id, run.tool_id))
        if run.events is not None:
            events.append(run.events)
        elif summary is not None:
            events.append(summary.events)
    return ProgramColumns(
        program_id=program_id,
        program_name=runs[-1].program_name,
        runs=len(runs),
        noks=sum(1 for run in runs if run.result == "NOK"),
        values=values,
        latest_windows=latest_windows,
        window_counts=window_counts,
        nok_reasons=nok_reasons,
        stop_reasons=Counter(run.stop_reason or TOOL_STOPPED for run in runs),
        staged_runs=sum(1 for run in runs if run.pulses is not None),
        pulsed_runs=sum(1 for run in runs if run.pulses),
        events_per_run=events,
        stations=sorted({run.station for run in runs}),
        tools=sorted({run.tool_id for run in runs}),
    )
