"""The statistics of one program over its results: what ``boltwatch report`` shows of it.

Per figure (final torque, angle, preload, process intensity): the values of
the runs that measured it, in the order the runs ended, their capability
against the program's window (:mod:`.capability`) and their control chart
(:mod:`.control_chart`). Per program: the NOK rate, a Pareto of NOK reasons
(each ``"; "``-separated reason counted once per run by its kind, the text
before its figures, ``preload low``; most frequent first),
the stop reasons (``tool`` when the tool stopped by itself) and the stick-slip
events per run. A multi-spindle station's program has, after its statistics
over every run, each spindle's (:attr:`ProgramStatistics.spindle`).

The window of a figure is the one the runs were judged against (carried by
each :class:`TighteningResult`); when it changed within the range, the
latest one is used and :attr:`ProgramStatistics.window_changes` says so.
Counts of equal size are listed by name. Made from a program's columns
(:mod:`.program_columns`): the results store's, or those of results read
from recordings (:func:`program_statistics`).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from shared.contract import RunSummary, TighteningResult
from shared.quality.capability import Capability, capability
from shared.quality.control_chart import ControlChart, control_chart
from shared.quality.program_columns import ProgramColumns, columns_of

#: (key, title, unit) of each figure, in the report's order
FIGURES = (
    ("torque", "final torque", "Nm"),
    ("angle", "final angle", "deg"),
    ("preload", "final preload", "N"),
    ("intensity", "process intensity", ""),
)


@dataclass(frozen=True, slots=True)
class FigureStatistics:
    """One figure of one program: its values, capability and chart."""

    key: str
    title: str
    unit: str
    values: np.ndarray  # the runs that measured it, in the order they ended
    capability: Capability
    chart: ControlChart | None  # None: fewer runs than one subgroup


@dataclass
class ProgramStatistics:
    """Everything the report says of one program."""

    program_id: int
    program_name: str
    runs: int
    noks: int
    figures: list[FigureStatistics]
    nok_reasons: list[tuple[str, int]]  # Pareto: most frequent first
    stop_reasons: list[tuple[str, int]]
    events_per_run: list[int]
    window_changes: list[str] = field(default_factory=list)
    stations: list[str] = field(default_factory=list)
    tools: list[int] = field(default_factory=list)
    #: runs that ran a final stage, and of them those that needed a pulse (a quality signal:
    #: a slip during the halt, won back)
    staged_runs: int = 0
    pulsed_runs: int = 0
    #: one spindle's runs of a multi-spindle station; None: every run of the program
    spindle: int | None = None

    @property
    def nok_rate(self) -> float:
        return self.noks / self.runs if self.runs else 0.0

    @property
    def name(self) -> str:
        """``program 1 (M14 ...)``, and its spindle when it is one spindle's."""
        named = f"program {self.program_id} ({self.program_name or 'unnamed'})"
        return named if self.spindle is None else f"{named} spindle {self.spindle}"


def program_statistics(
    results: Sequence[TighteningResult],
    subgroup_size: int,
    summaries: Mapping[tuple[str, int, int], RunSummary] | None = None,
) -> list[ProgramStatistics]:
    """One :class:`ProgramStatistics` per program id of ``results`` (in time order)."""
    return [statistics_of(columns, subgroup_size) for columns in columns_of(results, summaries)]


def _most_common(counts: Counter[str]) -> list[tuple[str, int]]:
    """Most frequent first; equal counts by name (the same order from any source)."""
    return sorted(counts.items(), key=lambda item: (-item[1], item[0]))


def statistics_of(columns: ProgramColumns, subgroup_size: int) -> ProgramStatistics:
    """The statistics of one program's columns."""
    figures, changes = [], []
    for key, title, unit in FIGURES:
        values = columns.values[key]
        lower, upper = columns.latest_windows.get(key, (None, None))
        windows = columns.window_counts.get(key, 0)
        if windows > 1:
            changes.append(f"{title}: {windows} windows in the range, the latest used")
        figures.append(
            FigureStatistics(
                key,
                title,
                unit,
                values,
                capability(values, lower, upper),
                control_chart(values, subgroup_size),
            )
        )
    return ProgramStatistics(
        program_id=columns.program_id,
        program_name=columns.program_name,
        runs=columns.runs,
        noks=columns.noks,
        figures=figures,
        nok_reasons=_most_common(columns.nok_reasons),
        stop_reasons=_most_common(columns.stop_reasons),
        events_per_run=columns.events_per_run,
        window_changes=changes,
        stations=columns.stations,
        tools=columns.tools,
        staged_runs=columns.staged_runs,
        pulsed_runs=columns.pulsed_runs,
        spindle=columns.spindle,
    )
