"""When a tool's work last changed: the day its pace is measured from (pure).

A tool moved to another station, or a station that began a new program, wears
the tool at a new pace from that day: days before it say little of the days
to come. :func:`work_changed` finds, among the tool's complete production days
in the pace's window (its runs grouped by day, station and program):

- **a move**: the stations that made at least :data:`MAIN_SHARE` of a day's
  intensity are the newest day's on every day since some day, and were not
  on the day before it;
- **a new program**: a station's program that makes at least
  :data:`MAIN_SHARE` of the intensity since some day, with no run in the
  window before that day (and the window reaching at least
  :data:`SEEN_BEFORE_DAYS` production days further back, so a program
  merely older than the window is not new).

The later of the two is the day; the forecast's pace
(:func:`~.wear_forecast.wear_pace`) is measured from it once the tool ran on
:attr:`~.wear_forecast.ForecastSettings.min_days_since_change` days since.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from shared.wear.wear_grouped_runs import GroupedRuns

#: a station or program counts in a day's work with this share of its intensity
MAIN_SHARE = 0.1
#: a program is new when the window shows this many production days without it first
SEEN_BEFORE_DAYS = 5


@dataclass(frozen=True, slots=True)
class WorkChange:
    """The day the tool's work changed, and how, in words."""

    day: int
    what: str


def work_changed(groups: Sequence[GroupedRuns], first_day: int, today: int) -> WorkChange | None:
    """The newest change among the tool's days from ``first_day`` to before ``today``; None
    when its work stayed the same."""
    per_day: dict[int, dict[tuple[str, int], float]] = {}
    for group in groups:
        if first_day <= group.day < today and group.every_run > 0:
            work = per_day.setdefault(group.day, {})
            key = (group.station, group.program_id)
            work[key] = work.get(key, 0.0) + group.intensity
    days = sorted(per_day)
    if len(days) < 2:
        return None
    found = [change for change in (_moved(per_day, days), _new_program(per_day, days)) if change]
    return max(found, key=lambda change: change.day) if found else None


def _stations(work: dict[tuple[str, int], float]) -> frozenset[str]:
    total = sum(work.values())
    by_station: dict[str, float] = {}
    for (station, _), intensity in work.items():
        by_station[station] = by_station.get(station, 0.0) + intensity
    if total <= 0:
        return frozenset(by_station)
    return frozenset(name for name, value in by_station.items() if value >= MAIN_SHARE * total)


def _moved(per_day: dict[int, dict[tuple[str, int], float]], days: list[int]) -> WorkChange | None:
    newest = _stations(per_day[days[-1]])
    index = len(days) - 1
    while index > 0 and _stations(per_day[days[index - 1]]) == newest:
        index -= 1
    if index == 0:
        return None
    return WorkChange(days[index], f"moved to {', '.join(sorted(newest))}")


def _new_program(
    per_day: dict[int, dict[tuple[str, int], float]], days: list[int]
) -> WorkChange | None:
    first_seen: dict[tuple[str, int], int] = {}
    for day in days:
        for key in per_day[day]:
            first_seen.setdefault(key, day)
    newest: WorkChange | None = None
    for key, day in first_seen.items():
        if sum(1 for earlier in days if earlier < day) < SEEN_BEFORE_DAYS:
            continue
        since = [per_day[later] for later in days if later >= day]
        total = sum(sum(work.values()) for work in since)
        share = sum(work.get(key, 0.0) for work in since)
        if total > 0 and share >= MAIN_SHARE * total and (newest is None or day > newest.day):
            newest = WorkChange(day, f"program {key[1]} began at {key[0]}")
    return newest
