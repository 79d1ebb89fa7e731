"""The statistics of one program over its results: what ``boltwatch report`` shows of it.

Per figure (final torque, angle, preload, process intensity): the values of
the runs that measured it, in the order the runs ended, their capability
against the program's window (:mod:`.capability`) and their control chart
(:mod:`.control_chart`). Per program: the NOK rate, a Pareto of NOK reasons
(each ``"; "``-separated reason counted once per run by its kind, the text
before its figures, ``preload low``; most frequent first),
the stop reasons (``tool`` when the tool stopped by itself) and the stick-slip
events per run.

The window of a figure is the one the runs were judged against (carried by
each :class:`TighteningResult`); when it changed within the range, the
latest one is used and :attr:`ProgramStatistics.window_changes` says so.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from shared.contract import JudgedFigure, RunSummary, TighteningResult
from shared.quality.capability import Capability, capability
from shared.quality.control_chart import ControlChart, control_chart

#: (key, title, unit) of each figure, in the report's order
FIGURES = (
    ("torque", "final torque", "Nm"),
    ("angle", "final angle", "deg"),
    ("preload", "final preload", "N"),
    ("intensity", "process intensity", ""),
)
#: the stop reason shown for a run the tool stopped by itself (no StopCommand)
TOOL_STOPPED = "tool"


@dataclass(frozen=True, slots=True)
class FigureStatistics:
    """One figure of one program: its values, capability and chart."""

    key: str
    title: str
    unit: str
    values: list[float]
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

    @property
    def nok_rate(self) -> float:
        return self.noks / self.runs if self.runs else 0.0


def reason_kind(reason: str) -> str:
    """What a NOK reason says without its figures: ``preload low: 52800 N, window 53000 to
    59000 N`` -> ``preload low`` (the Pareto counts kinds, not values)."""
    return reason.split(":", 1)[0].strip()


def _judged(result: TighteningResult, key: str) -> JudgedFigure | None:
    return {
        "torque": result.final_torque_nm,
        "angle": result.final_angle_deg,
        "preload": result.final_force_n,
    }.get(key)


def _value(result: TighteningResult, key: str) -> float | None:
    if key == "intensity":
        return result.process_intensity
    judged = _judged(result, key)
    return judged.value if judged is not None else None


def program_statistics(
    results: Sequence[TighteningResult],
    subgroup_size: int,
    summaries: Mapping[tuple[str, int, int], RunSummary] | None = None,
) -> list[ProgramStatistics]:
    """One :class:`ProgramStatistics` per program id of ``results`` (in time order)."""
    by_program: dict[int, list[TighteningResult]] = {}
    for result in results:
        by_program.setdefault(result.program_id, []).append(result)
    return [
        _one_program(program_id, runs, subgroup_size, summaries or {})
        for program_id, runs in sorted(by_program.items())
    ]


def _one_program(
    program_id: int,
    runs: list[TighteningResult],
    subgroup_size: int,
    summaries: Mapping[tuple[str, int, int], RunSummary],
) -> ProgramStatistics:
    latest = runs[-1]
    figures, changes = [], []
    for key, title, unit in FIGURES:
        values = [value for value in (_value(run, key) for run in runs) if value is not None]
        judged = _judged(latest, key)
        lower, upper = (judged.min, judged.max) if judged is not None else (None, None)
        windows = {(j.min, j.max) for j in (_judged(run, key) for run in runs) if j is not None}
        if len(windows) > 1:
            changes.append(f"{title}: {len(windows)} windows in the range, the latest used")
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
    reasons: Counter[str] = Counter()
    for run in runs:
        if run.result == "NOK":
            reasons.update({reason_kind(reason) for reason in run.nok_reasons.split(";")} - {""})
    stops = Counter(run.stop_reason or TOOL_STOPPED for run in runs)
    events = []
    for run in runs:
        summary = summaries.get((run.station, run.run_id, run.tool_id))
        if run.events is not None:
            events.append(run.events)
        elif summary is not None:
            events.append(summary.events)
    return ProgramStatistics(
        program_id=program_id,
        program_name=latest.program_name,
        runs=len(runs),
        noks=sum(1 for run in runs if run.result == "NOK"),
        figures=figures,
        nok_reasons=reasons.most_common(),
        stop_reasons=stops.most_common(),
        events_per_run=events,
        window_changes=changes,
        stations=sorted({run.station for run in runs}),
        tools=sorted({run.tool_id for run in runs}),
    )
