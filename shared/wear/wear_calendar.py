"""The plant's production calendar, learned from the wear ledger's own runs (pure, numpy).

A forecast of a tool's service is counted in production days, so it needs
to know which days the line works and when in the day: nobody types that
in; the ledger's runs say it. :func:`learn_calendar` takes the end times of
(a sample of) the line's runs over the last weeks and finds:

- **when a production day starts**: the end of the longest quiet stretch
  of the day (the quarter hours with the fewest runs, taken round the clock
  at UTC): a two-shift line's day starts with its first shift, a three-shift
  line's at its quietest shift change;
- **which weekdays are worked**, and how much: a weekday is worked when it
  had production (at least a fifth of a median day's runs) in at least half
  of the weeks seen; its weight is its runs per worked day against the
  average worked day (a Saturday of one shift beside weekdays of two: about
  0.5). A holiday is a day with no production: it is left out of the
  weight, and a weekday worked in most weeks stays worked;
- **its shifts**: per weekday, the stretches of quarter hours with
  production, split where production drops below half of the stretch's
  median (the hand-over between two shifts); a stretch shorter than an hour
  joins its neighbour. Within a day, time counts in worked time only
  (:meth:`ProductionCalendar.worked_fraction`): a production day is 0 at its
  first shift's start and 1 at its last shift's end.

Times are integer nanoseconds since the Unix epoch; a production day is an
integer, the days since 1970-01-01 of its UTC date (the date it starts on, or the
next one for a day that starts in the evening: a plant's local time needs no
zone, the day's start is learned in UTC).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

DAY_S = 86_400
DAY_NS = DAY_S * 1_000_000_000
SLOT_S = 900  # a quarter hour
SLOTS = DAY_S // SLOT_S
WEEK_DAYS = 7
#: 1970-01-01 was a Thursday: the weekday (Monday 0) of day 0
_EPOCH_WEEKDAY = 3
#: a calendar is learned from at least this much history (one of each weekday)
MIN_SPAN_DAYS = 7
#: a day with fewer runs than this share of a median production day had no production
PRODUCTION_DAY_SHARE = 0.2
#: a weekday is worked when it had production in at least this share of the weeks seen
WORKED_WEEKS_SHARE = 0.5
#: a quarter hour with fewer runs than this share of a busy one (the weekday's 90th
#: percentile) has no production
ACTIVE_SLOT_SHARE = 0.1
#: a shift change: production below this share of its stretch's median quarter hour
HANDOVER_SHARE = 0.5
#: a shift is at least this long (a shorter piece joins its neighbour)
MIN_SHIFT_S = 3600


@dataclass(frozen=True, slots=True)
class Shift:
    """A stretch of production within a production day, in seconds after the day's start."""

    start_s: int
    end_s: int

    @property
    def length_s(self) -> int:
        return self.end_s - self.start_s


@dataclass(frozen=True, slots=True)
class ProductionWeekday:
    """One weekday of the plant (of the date its production day starts on)."""

    #: its production against an average worked day (0: not worked)
    weight: float
    shifts: list[Shift] = field(default_factory=list)

    @property
    def worked_s(self) -> int:
        return sum(shift.length_s for shift in self.shifts)


@dataclass(frozen=True, slots=True)
class ProductionCalendar:
    """When the plant works, as its runs showed (Monday first)."""

    #: seconds after UTC midnight at which a production day starts (-12 h to 12 h: a day that
    #: starts in the evening is the next date's)
    day_start_s: int
    weekdays: list[ProductionWeekday]
    learned_from_ns: int  # the oldest run it was learned from
    learned_until_ns: int  # the newest
    runs: int  # how many runs it was learned from (a sample of the ledger's)

    def day_of(self, time_ns: int) -> int:
        """The production day ``time_ns`` falls in."""
        return (time_ns - self.day_start_s * 1_000_000_000) // DAY_NS

    def day_start_ns(self, day: int) -> int:
        return day * DAY_NS + self.day_start_s * 1_000_000_000

    @staticmethod
    def weekday(day: int) -> int:
        """Monday 0 ... Sunday 6."""
        return (day + _EPOCH_WEEKDAY) % WEEK_DAYS

    def of_day(self, day: int) -> ProductionWeekday:
        return self.weekdays[self.weekday(day)]

    def worked(self, day: int) -> bool:
        return self.of_day(day).weight > 0

    def worked_fraction(self, time_ns: int) -> float:
        """How much of its production day's worked time has passed at ``time_ns`` (0 to 1;
        0 on a day not worked)."""
        day = self.day_of(time_ns)
        weekday = self.of_day(day)
        total = weekday.worked_s
        if total == 0:
            return 0.0
        offset_s = (time_ns - self.day_start_ns(day)) / 1e9
        elapsed = sum(
            min(max(offset_s - shift.start_s, 0.0), shift.length_s) for shift in weekday.shifts
        )
        return elapsed / total

    def time_at(self, day: int, fraction: float) -> int:
        """The moment when ``fraction`` of ``day``'s worked time has passed (its start for
        a day not worked)."""
        weekday = self.of_day(day)
        start_ns = self.day_start_ns(day)
        left_s = max(0.0, min(fraction, 1.0)) * weekday.worked_s
        for shift in weekday.shifts:
            if left_s <= shift.length_s:
                return start_ns + int((shift.start_s + left_s) * 1e9)
            left_s -= shift.length_s
        return start_ns + (weekday.shifts[-1].end_s * 1_000_000_000 if weekday.shifts else 0)

    def shift_at(self, time_ns: int) -> tuple[int, int] | None:
        """The shift ``time_ns`` falls in (its start and end), or the next one to start
        after it; None when no day within a week is worked."""
        day = self.day_of(time_ns)
        for ahead in range(WEEK_DAYS + 1):
            start_ns = self.day_start_ns(day + ahead)
            for shift in self.of_day(day + ahead).shifts:
                end_ns = start_ns + shift.end_s * 1_000_000_000
                if end_ns > time_ns:
                    return start_ns + shift.start_s * 1_000_000_000, end_ns
        return None

    @classmethod
    def from_dict(cls, fields: dict[str, Any]) -> ProductionCalendar:
        return cls(
            day_start_s=int(fields["day_start_s"]),
            weekdays=[
                ProductionWeekday(
                    float(weekday["weight"]),
                    [
                        Shift(int(shift["start_s"]), int(shift["end_s"]))
                        for shift in weekday["shifts"]
                    ],
                )
                for weekday in fields["weekdays"]
            ],
            learned_from_ns=int(fields["learned_from_ns"]),
            learned_until_ns=int(fields["learned_until_ns"]),
            runs=int(fields["runs"]),
        )


def learn_calendar(ended_ns: Sequence[int] | np.ndarray) -> ProductionCalendar | None:
    """The calendar the runs ending at ``ended_ns`` show; None when they span less than
    :data:`MIN_SPAN_DAYS` days (not every weekday seen)."""
    times = np.sort(np.asarray(ended_ns, dtype=np.int64))
    if times.size == 0 or int(times[-1] - times[0]) < MIN_SPAN_DAYS * DAY_NS:
        return None
    seconds = times // 1_000_000_000
    day_start_s = _day_start_s(np.bincount((seconds % DAY_S) // SLOT_S, minlength=SLOTS))
    if day_start_s >= DAY_S // 2:  # an evening start: the day is the next date's
        day_start_s -= DAY_S
    shifted = seconds - day_start_s
    days = shifted // DAY_S
    slots = (shifted % DAY_S) // SLOT_S
    first_day, last_day = int(days[0]), int(days[-1])
    # the first and the last day may be partial: counted only when the span leaves others
    whole = np.arange(first_day + 1, last_day) if last_day - first_day > 2 else np.arange(0)
    per_day = np.bincount(days - first_day, minlength=last_day - first_day + 1)
    counts = per_day[whole - first_day] if whole.size else per_day
    days_seen = whole if whole.size else np.arange(first_day, last_day + 1)
    busy = counts[counts > 0]
    floor = PRODUCTION_DAY_SHARE * float(np.median(busy)) if busy.size else 0.0
    produced = counts >= max(floor, 1.0)
    weekday_of_day = (days_seen + _EPOCH_WEEKDAY) % WEEK_DAYS
    mean_worked = float(counts[produced].mean()) if produced.any() else 0.0
    weekdays = []
    all_profile = np.bincount(slots, minlength=SLOTS).astype(float)
    for weekday in range(WEEK_DAYS):
        seen = weekday_of_day == weekday
        worked_days = seen & produced
        if not seen.any() or worked_days.sum() < WORKED_WEEKS_SHARE * seen.sum():
            weekdays.append(ProductionWeekday(0.0))
            continue
        weight = float(counts[worked_days].mean()) / mean_worked if mean_worked else 1.0
        mask = np.isin(days, days_seen[worked_days])
        profile = np.bincount(slots[mask], minlength=SLOTS).astype(float)
        if int(worked_days.sum()) < 2:  # one day of this weekday: the shape of every day
            profile = all_profile
        weekdays.append(ProductionWeekday(weight, _shifts(profile)))
    return ProductionCalendar(
        day_start_s=int(day_start_s),
        weekdays=weekdays,
        learned_from_ns=int(times[0]),
        learned_until_ns=int(times[-1]),
        runs=int(times.size),
    )


def _day_start_s(per_slot: np.ndarray) -> int:
    """The end of the longest run of quietest quarter hours, round the clock (seconds)."""
    low, high = float(per_slot.min()), float(per_slot.max())
    quiet = per_slot <= low + 0.1 * (high - low)
    if quiet.all():
        return 0
    best_length, best_end = 0, 0
    for start in range(SLOTS):  # runs of quiet slots, circularly: at most 96 × 96 steps
        if not quiet[start] or quiet[(start - 1) % SLOTS]:
            continue
        length = 0
        while quiet[(start + length) % SLOTS] and length < SLOTS:
            length += 1
        if length > best_length:
            best_length, best_end = length, (start + length) % SLOTS
    return best_end * SLOT_S


def _shifts(profile: np.ndarray) -> list[Shift]:
    """The shifts of one weekday's quarter-hour profile (runs per quarter hour)."""
    nonzero = profile[profile > 0]
    if nonzero.size == 0:
        return []
    active = profile >= ACTIVE_SLOT_SHARE * float(np.percentile(nonzero, 90))
    shifts: list[Shift] = []
    slot = 0
    while slot < SLOTS:
        if not active[slot]:
            slot += 1
            continue
        end = slot
        while end < SLOTS and active[end]:
            end += 1
        shifts.extend(_split_at_handovers(profile, slot, end))
        slot = end
    return shifts


def _split_at_handovers(profile: np.ndarray, start: int, end: int) -> list[Shift]:
    """One stretch of production [start, end) (quarter hours), split at its hand-overs."""
    level = float(np.median(profile[start:end]))
    low = profile[start:end] < HANDOVER_SHARE * level
    pieces: list[tuple[int, int]] = []
    piece_start: int | None = None
    for index in range(start, end):
        if low[index - start]:
            if piece_start is not None:
                pieces.append((piece_start, index))
                piece_start = None
        elif piece_start is None:
            piece_start = index
    if piece_start is not None:
        pieces.append((piece_start, end))
    merged: list[list[int]] = []
    for piece_start, piece_end in pieces:
        if merged and (piece_end - piece_start) * SLOT_S < MIN_SHIFT_S:
            merged[-1][1] = piece_end  # too short for a shift: part of the one before
        elif merged and (merged[-1][1] - merged[-1][0]) * SLOT_S < MIN_SHIFT_S:
            merged[-1][1] = piece_end
        else:
            merged.append([piece_start, piece_end])
    return [Shift(first * SLOT_S, last * SLOT_S) for first, last in merged]
