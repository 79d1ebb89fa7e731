"""A simulated plant's months of production in a wear ledger: what the forecast is judged on.

:func:`simulate` plays a plant of a :class:`PlantShape` from a seed: its
stations run their programs in shifts on its worked weekdays (a plant's local
time, written in UTC as a real ledger holds it), with a hand-over between
shifts, holidays, a station down for hours now and then, the day's volume
wandering (a log-normal factor, autocorrelated from day to day), each
program's intensity per run log-normal around its own median, a program
added at one station midway, and tools swapped between two stations. Each
tool is serviced at the first shift change after its intensity since service
crosses the plant's threshold (its crossing: the run that took it over). The
plant's own calendar (:class:`TrueCalendar`) says how many production days
lie between two moments, which is what a forecast's error is counted in.

:func:`write_ledger` writes the runs and services into a real wear ledger
(:class:`shared.wear.WearLedger` makes it; the rows go in by SQL, months of
runs at once). :func:`ledger_forecasts` gives a ledger's tools and their forecasts
soonest first, as a page ranks them.
"""

from __future__ import annotations

import bisect
import sqlite3
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime, timedelta
from pathlib import Path

import numpy as np

from shared.wear import ToolForecast, ToolWear, WearLedger, forecast

DAY_NS = 86_400 * 1_000_000_000
HOUR_NS = 3_600 * 1_000_000_000
MINUTE_NS = 60 * 1_000_000_000


@dataclass(frozen=True, slots=True)
class PlantShape:
    """How a plant works; hours are its local time."""

    name: str
    #: shifts of a weekday (start hour, end hour; an end past 24 runs into the next date)
    shifts: tuple[tuple[float, float], ...]
    weekdays: tuple[int, ...]  # worked weekdays, Monday 0
    #: shifts of a Saturday when it is not one of ``weekdays`` but worked anyway (none: not)
    saturday_shifts: tuple[tuple[float, float], ...] = ()
    utc_offset_h: float = 1.0  # local time minus UTC
    handover_min: float = 30.0  # no runs for this long at each shift change
    holidays: int = 3  # worked weekdays with no production
    stations: int = 5
    programs: tuple[int, int] = (1, 3)  # per station, at least and at most
    cycle_s: tuple[float, float] = (60.0, 150.0)  # a station's mean time between runs
    volume_sd: float = 0.08  # day-to-day step of the log volume factor
    volume_memory: float = 0.7  # its autocorrelation from one day to the next
    downtime_per_day: float = 0.04  # chance a station is down for 2 to 8 hours of a day
    program_added_day: int | None = 60  # a program added at one station (None: never)
    swap_day: int | None = 90  # two stations' tools swapped (None: never)
    wear_trend: float = 0.0  # a tool's intensity per run grows by this share over 30 days
    days: int = 240  # calendar days played
    interval_days: float = 40.0  # the threshold: a median tool's production days to it
    unusual_runs: float = 2e-4  # chance a run takes ten times its program's intensity


TWO_SHIFTS = PlantShape("two shifts, Mon-Fri", ((6, 14), (14, 22)), (0, 1, 2, 3, 4))
THREE_SHIFTS = PlantShape(
    "three shifts, Mon-Fri, Saturday mornings",
    ((6, 14), (14, 22), (22, 30)),
    (0, 1, 2, 3, 4),
    saturday_shifts=((6, 14),),
    utc_offset_h=-5.0,
    handover_min=20.0,
    holidays=2,
    stations=6,
    cycle_s=(45.0, 120.0),
    program_added_day=75,
    swap_day=110,
)
ONE_SHIFT = PlantShape(
    "one shift, Mon-Sat, a lunch break",
    ((7, 11.5), (12, 16.5)),
    (0, 1, 2, 3, 4, 5),
    utc_offset_h=8.0,
    handover_min=0.0,
    holidays=4,
    stations=4,
    cycle_s=(40.0, 90.0),
    volume_sd=0.12,
    downtime_per_day=0.06,
    program_added_day=100,
    swap_day=50,
    wear_trend=0.1,
)
SHAPES = {"two": TWO_SHIFTS, "three": THREE_SHIFTS, "one": ONE_SHIFT}


@dataclass
class TrueCalendar:
    """The plant's production as it was: its worked stretches, in order (ns)."""

    stretches: list[tuple[int, int]] = field(default_factory=list)  # (start, end) of each shift
    day_of_stretch: list[int] = field(default_factory=list)  # its production day's number

    def position(self, time_ns: int) -> float:
        """Production days up to ``time_ns``: whole days before it, and the worked share of
        its own production day."""
        index = bisect.bisect_right([start for start, _ in self.stretches], time_ns) - 1
        if index < 0:
            return 0.0
        day = self.day_of_stretch[index]
        first = self.day_of_stretch.index(day)
        last = first
        while last + 1 < len(self.stretches) and self.day_of_stretch[last + 1] == day:
            last += 1
        worked = sum(end - start for start, end in self.stretches[first : last + 1])
        done = sum(
            min(max(time_ns - start, 0), end - start)
            for start, end in self.stretches[first : last + 1]
        )
        return day + done / worked

    def time_at(self, position: float) -> int:
        """The moment at ``position`` production days (the inverse of :meth:`position`)."""
        day = int(position)
        fraction = position - day
        members = [i for i, d in enumerate(self.day_of_stretch) if d == day]
        if not members:
            return self.stretches[-1][1] if day > 0 else self.stretches[0][0]
        worked = sum(self.stretches[i][1] - self.stretches[i][0] for i in members)
        left = fraction * worked
        for i in members:
            start, end = self.stretches[i]
            if left <= end - start:
                return int(start + left)
            left -= end - start
        return self.stretches[members[-1]][1]


@dataclass(frozen=True, slots=True)
class Crossing:
    """A tool's intensity since service crossing the threshold."""

    tool_id: int
    interval_start_ns: int  # its service before (or its first run)
    crossed_ns: int  # the run that took it over
    serviced_ns: int  # the service recorded after it


@dataclass
class Plant:
    shape: PlantShape
    seed: int
    start_ns: int
    threshold: float
    calendar: TrueCalendar
    #: every run, by end time: station index, run id, tool, program, intensity, end (ns)
    station: np.ndarray
    run_id: np.ndarray
    tool_id: np.ndarray
    program_id: np.ndarray
    intensity: np.ndarray
    ended_ns: np.ndarray
    crossings: list[Crossing]
    station_names: list[str]
    #: when each tool ran first
    first_run_ns: dict[int, int]

    @property
    def end_ns(self) -> int:
        return int(self.ended_ns[-1])


def _local_midnight_ns(start: datetime, day: int, offset_h: float) -> int:
    return int(start.timestamp() * 1e9) + day * DAY_NS - int(offset_h * HOUR_NS)


def _worked_days(
    shape: PlantShape, rng: np.random.Generator, start: datetime
) -> tuple[TrueCalendar, list[tuple[int, list[tuple[int, int]]]]]:
    """The plant's calendar, and each worked day with its shifts (ns)."""
    worked = [day for day in range(shape.days) if day % 7 in shape.weekdays]
    holidays = set(rng.choice(worked[5:], size=shape.holidays, replace=False).tolist())
    calendar = TrueCalendar()
    day_shifts: list[tuple[int, list[tuple[int, int]]]] = []
    for day in range(shape.days):
        if day % 7 in shape.weekdays and day not in holidays:
            hours = shape.shifts
        elif day % 7 == 5 and shape.saturday_shifts and day not in holidays:
            hours = shape.saturday_shifts
        else:
            continue
        midnight = _local_midnight_ns(start, day, shape.utc_offset_h)
        gap = int(shape.handover_min * MINUTE_NS / 2)
        stretches = [
            (midnight + int(begin * HOUR_NS) + gap, midnight + int(end * HOUR_NS) - gap)
            for begin, end in hours
        ]
        for stretch in stretches:
            calendar.stretches.append(stretch)
            calendar.day_of_stretch.append(len(day_shifts))
        day_shifts.append((day, stretches))
    return calendar, day_shifts


def simulate(shape: PlantShape, seed: int, start: datetime | None = None) -> Plant:
    """``shape``'s plant played for its days from ``start`` (a Monday, 00:00 local; default
    2026-01-05)."""
    rng = np.random.default_rng(seed)
    start = start or datetime(2026, 1, 5, tzinfo=UTC)
    calendar, day_shifts = _worked_days(shape, rng, start)
    station_names = [f"st{index + 1}" for index in range(shape.stations)]
    cycles = rng.uniform(*shape.cycle_s, size=shape.stations)
    programs = []  # per station: (program ids, medians, sigmas, mix)
    next_program = 1
    for _ in range(shape.stations):
        count = int(rng.integers(shape.programs[0], shape.programs[1] + 1))
        ids = list(range(next_program, next_program + count))
        next_program += count
        medians = np.exp(rng.uniform(np.log(5e4), np.log(4e5), size=count))
        sigmas = rng.uniform(0.25, 0.5, size=count)
        programs.append((ids, medians, sigmas, rng.dirichlet(np.ones(count) * 3)))
    added_station = int(rng.integers(shape.stations))
    added_program = next_program
    tools = [100 + index for index in range(shape.stations)]
    swap: list[int] = (
        rng.choice(shape.stations, size=2, replace=False).tolist() if shape.stations > 1 else []
    )

    columns: dict[str, list[np.ndarray]] = {k: [] for k in ("st", "tool", "prog", "i", "end")}
    volume = np.zeros(shape.stations)
    for day, stretches in day_shifts:
        volume = shape.volume_memory * volume + rng.normal(0, shape.volume_sd, shape.stations)
        for index in range(shape.stations):
            down = None
            if rng.random() < shape.downtime_per_day:
                span = stretches[-1][1] - stretches[0][0]
                length = min(int(rng.uniform(2, 8) * HOUR_NS), span // 2)
                begin = int(rng.uniform(stretches[0][0], stretches[-1][1] - length))
                down = (begin, begin + length)
            tool = tools[index]
            if shape.swap_day is not None and day >= shape.swap_day and index in swap:
                tool = tools[int(swap[1] if index == swap[0] else swap[0])]
            ids, medians, sigmas, mix = programs[index]
            if (
                shape.program_added_day is not None
                and day >= shape.program_added_day
                and (index == added_station)
            ):
                ids = [*ids, added_program]
                medians = np.append(medians, 2.0 * float(np.max(medians)))
                sigmas = np.append(sigmas, 0.35)
                mix = np.append(mix * 0.7, 0.3)
            for begin, end in stretches:
                mean = (end - begin) / 1e9 / cycles[index] * np.exp(volume[index])
                times = np.sort(rng.uniform(begin, end, size=rng.poisson(mean))).astype(np.int64)
                if down is not None:
                    times = times[(times < down[0]) | (times >= down[1])]
                which = rng.choice(len(ids), size=times.size, p=mix / mix.sum())
                values = np.exp(
                    np.log(medians[which]) + sigmas[which] * rng.normal(size=times.size)
                )
                values *= np.where(rng.random(times.size) < shape.unusual_runs, 10.0, 1.0)
                columns["st"].append(np.full(times.size, index))
                columns["tool"].append(np.full(times.size, tool))
                columns["prog"].append(np.array(ids)[which])
                columns["i"].append(values)
                columns["end"].append(times)
    station = np.concatenate(columns["st"])
    tool_id = np.concatenate(columns["tool"])
    program_id = np.concatenate(columns["prog"])
    intensity = np.concatenate(columns["i"])
    ended_ns = np.concatenate(columns["end"])
    order = np.argsort(ended_ns, kind="stable")
    station, tool_id, program_id, intensity, ended_ns = (
        column[order] for column in (station, tool_id, program_id, intensity, ended_ns)
    )
    first_run_ns = {int(t): int(ended_ns[tool_id == t][0]) for t in np.unique(tool_id)}
    threshold = _threshold(shape, tool_id, intensity, ended_ns, calendar)
    intensity, crossings = _services(shape, calendar, tool_id, intensity, ended_ns, threshold)
    return Plant(
        shape=shape,
        seed=seed,
        start_ns=int(start.timestamp() * 1e9),
        threshold=threshold,
        calendar=calendar,
        station=station,
        run_id=np.arange(1, ended_ns.size + 1),
        tool_id=tool_id,
        program_id=program_id,
        intensity=intensity,
        ended_ns=ended_ns,
        crossings=crossings,
        station_names=station_names,
        first_run_ns=first_run_ns,
    )


def _threshold(
    shape: PlantShape,
    tool_id: np.ndarray,
    intensity: np.ndarray,
    ended_ns: np.ndarray,
    calendar: TrueCalendar,
) -> float:
    """The median tool's intensity over ``shape.interval_days`` production days."""
    days = max(calendar.day_of_stretch) + 1
    per_day = [float(intensity[tool_id == tool].sum()) / days for tool in np.unique(tool_id)]
    del ended_ns
    return float(np.median(per_day)) * shape.interval_days


def _services(
    shape: PlantShape,
    calendar: TrueCalendar,
    tool_id: np.ndarray,
    intensity: np.ndarray,
    ended_ns: np.ndarray,
    threshold: float,
) -> tuple[np.ndarray, list[Crossing]]:
    """Each tool serviced at the first shift change after each crossing; a worn tool takes
    ``shape.wear_trend`` more per run for each 30 days since its service (up to 90 days)."""
    ends = [end for _, end in calendar.stretches]
    crossings = []
    taken = intensity.copy()
    for tool in np.unique(tool_id):
        rows = np.flatnonzero(tool_id == tool)
        start_ns = int(ended_ns[rows[0]]) - 1
        position = 0
        while position < rows.size:
            chosen = rows[position:]
            age_days = np.minimum((ended_ns[chosen] - start_ns) / DAY_NS, 90.0)
            worn = intensity[chosen] * (1.0 + shape.wear_trend * age_days / 30.0)
            cumulative = np.cumsum(worn)
            over = int(np.searchsorted(cumulative, threshold))
            if over >= chosen.size:
                taken[chosen] = worn
                break
            crossed_ns = int(ended_ns[chosen[over]])
            later = bisect.bisect_right(ends, crossed_ns)
            serviced_ns = ends[later] if later < len(ends) else crossed_ns + HOUR_NS
            before = ended_ns[chosen] <= serviced_ns
            taken[chosen[before]] = worn[before]
            crossings.append(Crossing(int(tool), start_ns, crossed_ns, serviced_ns))
            start_ns = serviced_ns
            position = int(np.searchsorted(ended_ns[rows], serviced_ns, side="right"))
    return taken, crossings


def write_ledger(plant: Plant, path: Path) -> None:
    """The plant's runs and services in a new wear ledger at ``path``."""
    WearLedger(path).close()
    rows = (
        (
            plant.station_names[int(plant.station[i])],
            int(plant.run_id[i]),
            int(plant.tool_id[i]),
            int(plant.program_id[i]),
            "done",
            "plateau_closest",
            10,
            float(plant.intensity[i]),
            int(plant.ended_ns[i]) - 3_000_000_000,
            int(plant.ended_ns[i]),
            int(plant.ended_ns[i]),
            "tightening",
        )
        for i in range(plant.ended_ns.size)
    )
    db = sqlite3.connect(path)
    try:
        with db:
            db.executemany("INSERT INTO runs VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)", rows)
            db.executemany(
                "INSERT INTO services (tool_id, serviced_ns, note) VALUES (?, ?, ?)",
                [(c.tool_id, c.serviced_ns, "simulated service") for c in plant.crossings],
            )
    finally:
        db.close()


def plant_until(shape: PlantShape, seed: int, now_ns: int) -> Plant:
    """``shape``'s plant over its days up to ``now_ns``: started on the Monday ``shape.days``
    days or more before, its runs and services after ``now_ns`` left out."""
    now = datetime.fromtimestamp(now_ns / 1e9, UTC)
    first = (now - timedelta(days=shape.days)).replace(hour=0, minute=0, second=0, microsecond=0)
    first -= timedelta(days=first.weekday())
    days = (now - first).days + 1
    plant = simulate(replace(shape, days=days), seed, first)
    kept = plant.ended_ns <= now_ns
    for name in ("station", "run_id", "tool_id", "program_id", "intensity", "ended_ns"):
        setattr(plant, name, getattr(plant, name)[kept])
    plant.crossings = [c for c in plant.crossings if c.serviced_ns <= now_ns]
    return plant


def ledger_forecasts(
    path: Path, threshold: float, now_ns: int
) -> tuple[dict[int, ToolWear], list[ToolForecast]]:
    """The ledger at ``path``'s tools by id, and each one's forecast at ``now_ns`` soonest
    first, as a page ranks them: due now, then by date, then those with no date."""
    with WearLedger(path, read_only=True) as ledger:
        tools = {tool.tool_id: tool for tool in ledger.tools()}
    told = [
        forecast(
            tool_id,
            tool.outlook.pace if tool.outlook else None,
            tool.outlook.calendar if tool.outlook else None,
            tool.intensity_since_service,
            threshold,
            now_ns,
        )
        for tool_id, tool in tools.items()
    ]
    order = {"due": 0, "forecast": 1, "none": 2}
    return tools, sorted(told, key=lambda t: (order[t.state], t.due_ns or 0, t.tool_id))
