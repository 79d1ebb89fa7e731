"""What wears a tool, and how fast: its line of the ledger's outlook (pure).

From the tool's runs grouped by production day, station and program
(:mod:`.wear_history` reads them), :func:`tool_outlook` makes:

- its **pace** (:func:`~.wear_forecast.wear_pace`) and the plant's
  **calendar**, which the forecast against any threshold needs
  (:func:`~.wear_forecast.forecast`);
- **what wears it**: per station and program its runs since the service, their
  intensity, the intensity per run and the share of the tool's wear since
  the service (:class:`WearCause`; the joint is the program's joint at that
  station, where a station file names it);
- **what is unusual**: a station's program whose intensity per run over the
  last :data:`RECENT_DAYS` production days is at least :data:`UNUSUAL_RATIO`
  times its own history in the window before, and surely so (its mean at
  least :data:`UNUSUAL_SIGMAS` standard errors above); a run whose intensity
  is far above its program's history at that station (above the history's
  mean by :data:`UNUSUAL_RUN_SIGMAS` standard deviations and at least
  :data:`UNUSUAL_RATIO` times the mean: :class:`UnusualRun`);
- **the intensity since service by production day** (its cumulative sum at the
  end of each day, the line's page draws it against the threshold).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

from shared.wear.wear_calendar import DAY_NS, ProductionCalendar
from shared.wear.wear_change import work_changed
from shared.wear.wear_forecast import SHIPPED, DayWear, ForecastSettings, WearPace, wear_pace
from shared.wear.wear_grouped_runs import GroupedRuns

#: production days (today's included) whose intensity per run is compared with the history
RECENT_DAYS = 3
#: a program or run is named when it takes this many times its history's intensity per run
UNUSUAL_RATIO = 1.5
#: ... and its recent mean is this many standard errors above the history's
UNUSUAL_SIGMAS = 4.0
#: ... and a run this many of its program's standard deviations above the mean
UNUSUAL_RUN_SIGMAS = 6.0
#: a history of fewer runs says nothing unusual
MIN_HISTORY_RUNS = 20
#: at most this many points of the intensity since service (the oldest days thinned out)
MAX_POINTS = 60
#: at most this many unusual runs named
MAX_UNUSUAL_RUNS = 5


@dataclass(frozen=True, slots=True)
class WearCause:
    """One station's program: how much of the tool's wear since its service it made."""

    station: str
    program_id: int
    joint: str | None  # the program's joint at the station (None: no station file names it)
    runs: int  # its tightenings since the service
    every_run: int  # its runs of either kind since the service
    intensity: float  # their Σ I_process
    share: float  # of the tool's intensity since the service (0 to 1)
    per_run: float  # intensity per run since the service
    history_per_run: float | None  # per run over the window before the recent days
    recent_per_run: float | None  # per run over the recent days
    unusual: str | None  # why it is named (None: as usual)


@dataclass(frozen=True, slots=True)
class UnusualRun:
    """A run far above its program's history at its station."""

    station: str
    run_id: int
    program_id: int
    process_intensity: float
    ended_ns: int
    history_per_run: float  # its program's mean at the station
    ratio: float  # process_intensity / history_per_run


@dataclass(frozen=True, slots=True)
class RunLimit:
    """Above ``intensity``, a run of ``station``'s ``program_id`` is unusual."""

    station: str
    program_id: int
    intensity: float
    history_per_run: float


@dataclass(frozen=True, slots=True)
class ToolOutlook:
    """A tool's pace and causes of wear: what any forecast of it needs, and what wears it."""

    pace: WearPace
    calendar: ProductionCalendar | None
    #: (end of a production day, or now, ns; intensity since service up to then)
    since_service: list[tuple[int, float]] = field(default_factory=list)
    causes: list[WearCause] = field(default_factory=list)  # the largest share first
    unusual_runs: list[UnusualRun] = field(default_factory=list)  # the furthest above first

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, fields: Mapping[str, Any]) -> ToolOutlook:
        calendar = fields.get("calendar")
        return cls(
            pace=WearPace(**fields["pace"]),
            calendar=None if calendar is None else ProductionCalendar.from_dict(calendar),
            since_service=[(int(t), float(i)) for t, i in fields["since_service"]],
            causes=[WearCause(**cause) for cause in fields["causes"]],
            unusual_runs=[UnusualRun(**run) for run in fields["unusual_runs"]],
        )

    def shares(self, by: str) -> list[tuple[str, float, float]]:
        """(name, share, intensity per run) of the wear since service by ``by``: "program",
        "station" or "joint", the largest share first."""
        found: dict[str, list[float]] = {}
        for cause in self.causes:
            if by == "program":
                name = f"program {cause.program_id}"
            elif by == "station":
                name = cause.station
            else:
                name = cause.joint or "-"
            sums = found.setdefault(name, [0.0, 0.0, 0.0])
            sums[0] += cause.share
            sums[1] += cause.intensity
            sums[2] += cause.every_run
        rows = [
            (name, share, total / runs if runs else 0.0)
            for name, (share, total, runs) in found.items()
        ]
        return sorted(rows, key=lambda row: -row[1])


def tool_outlook(
    groups: Sequence[GroupedRuns],
    calendar: ProductionCalendar | None,
    first_run_ns: int,
    last_run_ns: int,
    last_service_ns: int | None,
    now_ns: int,
    joints: Mapping[tuple[str, int], str] | None = None,
    settings: ForecastSettings = SHIPPED,
) -> ToolOutlook:
    """The outlook from the tool's ``groups`` (since the older of its last service and the
    pace's window)."""
    days: dict[int, list[float]] = {}
    for group in groups:
        sums = days.setdefault(group.day, [0, 0, 0.0, 0.0])
        sums[0] += group.runs
        sums[1] += group.every_run
        sums[2] += group.intensity
        sums[3] += group.intensity_sq
    day_wear = [
        DayWear(day, int(runs), int(every), intensity, squares)
        for day, (runs, every, intensity, squares) in days.items()
    ]
    today = calendar.day_of(now_ns) if calendar is not None else now_ns // DAY_NS
    oldest = (
        calendar.day_of(now_ns - settings.window_days * DAY_NS) if calendar is not None else today
    )
    change = work_changed(groups, oldest, today)
    pace = wear_pace(day_wear, calendar, first_run_ns, last_run_ns, now_ns, settings, change)
    return ToolOutlook(
        pace=pace,
        calendar=calendar,
        since_service=_since_service(groups, calendar, last_service_ns, first_run_ns, now_ns),
        causes=_causes(groups, today, joints or {}),
    )


def _since_service(
    groups: Sequence[GroupedRuns],
    calendar: ProductionCalendar | None,
    last_service_ns: int | None,
    first_run_ns: int,
    now_ns: int,
) -> list[tuple[int, float]]:
    per_day: dict[int, float] = {}
    for group in groups:
        if group.after_service:
            per_day[group.day] = per_day.get(group.day, 0.0) + group.intensity
    start_ns = last_service_ns if last_service_ns is not None else first_run_ns
    points = [(start_ns, 0.0)]
    total = 0.0
    for day in sorted(per_day):
        total += per_day[day]
        end_ns = calendar.day_start_ns(day + 1) if calendar is not None else (day + 1) * DAY_NS
        points.append((min(end_ns, now_ns), total))
    if len(points) > MAX_POINTS:  # the first, the newest, and evenly between
        step = math.ceil((len(points) - 2) / (MAX_POINTS - 2))
        points = [points[0], *points[1:-1][::-1][::step][::-1], points[-1]]
    return points


def _causes(
    groups: Sequence[GroupedRuns], today: int, joints: Mapping[tuple[str, int], str]
) -> list[WearCause]:
    since: dict[tuple[str, int], list[float]] = {}
    history: dict[tuple[str, int], list[float]] = {}
    recent: dict[tuple[str, int], list[float]] = {}
    for group in groups:
        key = (group.station, group.program_id)
        if group.after_service:
            _add(since, key, group)
        _add(recent if group.day > today - RECENT_DAYS else history, key, group)
    total = sum(sums[2] for sums in since.values())
    causes = []
    for key, (runs, every, intensity, _) in since.items():
        before = history.get(key)
        now = recent.get(key)
        history_per_run = before[2] / before[1] if before and before[1] else None
        recent_per_run = now[2] / now[1] if now and now[1] else None
        causes.append(
            WearCause(
                station=key[0],
                program_id=key[1],
                joint=joints.get(key),
                runs=int(runs),
                every_run=int(every),
                intensity=intensity,
                share=intensity / total if total > 0 else 0.0,
                per_run=intensity / every if every else 0.0,
                history_per_run=history_per_run,
                recent_per_run=recent_per_run,
                unusual=_unusual_program(before, now),
            )
        )
    return sorted(causes, key=lambda cause: (-cause.intensity, cause.station, cause.program_id))


def _add(
    into: dict[tuple[str, int], list[float]], key: tuple[str, int], group: GroupedRuns
) -> None:
    sums = into.setdefault(key, [0, 0, 0.0, 0.0])
    sums[0] += group.runs
    sums[1] += group.every_run
    sums[2] += group.intensity
    sums[3] += group.intensity_sq


def _mean_sd(sums: list[float]) -> tuple[float, float]:
    count = sums[1]
    mean = sums[2] / count
    return mean, math.sqrt(max(sums[3] / count - mean * mean, 0.0))


def _unusual_program(before: list[float] | None, now: list[float] | None) -> str | None:
    """Why a program's recent runs are named, or None."""
    if not before or not now or before[1] < MIN_HISTORY_RUNS or now[1] < 5:
        return None
    mean, sd = _mean_sd(before)
    recent = now[2] / now[1]
    if mean <= 0 or recent < UNUSUAL_RATIO * mean:
        return None
    standard_error = sd / math.sqrt(now[1]) if sd > 0 else 0.0
    if standard_error > 0 and (recent - mean) / standard_error < UNUSUAL_SIGMAS:
        return None
    return (
        f"{recent / mean:.1f}× its own history per run over the last {RECENT_DAYS} production "
        f"days ({recent:.3g} against {mean:.3g})"
    )


def run_limits(
    groups: Sequence[GroupedRuns], calendar: ProductionCalendar | None, now_ns: int
) -> list[RunLimit]:
    """Per station and program, the intensity above which one of its runs is unusual: from
    its history (the window before the recent days; none with too few runs there)."""
    today = calendar.day_of(now_ns) if calendar is not None else now_ns // DAY_NS
    history: dict[tuple[str, int], list[float]] = {}
    for group in groups:
        if group.day <= today - RECENT_DAYS:
            _add(history, (group.station, group.program_id), group)
    limits = []
    for (station, program), sums in history.items():
        if sums[1] < MIN_HISTORY_RUNS:
            continue
        mean, sd = _mean_sd(sums)
        if mean > 0:
            limit = max(mean + UNUSUAL_RUN_SIGMAS * sd, UNUSUAL_RATIO * mean)
            limits.append(RunLimit(station, program, limit, mean))
    return limits
