"""A plant's year of tightening results, made up and written straight into a results store's
own tables, for ``bench_results_store.py`` and ``bench_results_migration.py``.

The plant (``Plant 1``): 20 stations (``st01``, named ``Station 01``, ...) on 2
lines (``st01``-``st10`` on ``L1``, ``st11``-``st20`` on ``L2``), 50 programs
(each station 2 or 3 of its own), 200 tools (10 a station). A part gets 4 to 8
bolts at one station, all by one program and one tool; part ids count per line
(``L1-P0000001``). Every fifth station is a tool controller's (Open Protocol: no
preload measured, 3 steps per result, a batch counter, no predictor figures);
the others are CAN stations judged by the predictor (torque, angle and preload
windows, stick-slip events, a process intensity). A figure is drawn in its
window (σ a quarter of the half-window) and about 1.5 % of the runs are pushed
out of one window, so NOK; each figure's status comes from
:func:`shared.quality.judge`. The runs are spread evenly over ``days`` (the
stations in turn, a little jitter): 10 million over a year is a run every 63 s
at each station.

The store is made by :class:`~shared.results.ResultsStore` first, so the
tables and indexes are the product's; then the rows go in as a bulk loader
would: SQLite by ``executemany`` in transactions of :data:`ROWS_PER_TRANSACTION`
(the loader's own connection: ``synchronous=OFF`` and a 1 GiB cache, which
only change how long loading takes), PostgreSQL by ``COPY`` (psycopg's
``cursor.copy``), then ``VACUUM ANALYZE`` (what autovacuum does to a table
after a large insert).
"""

from __future__ import annotations

import random
import sqlite3
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import psycopg

from shared.contract import JudgedFigure
from shared.quality import judge
from shared.results import (
    MIGRATIONS,
    SCHEMA_VERSION,
    ResultsDatabase,
    ResultsStore,
    StoreTarget,
    migrate,
)
from shared.results.results_schema import STEP_COLUMNS, TIGHTENING_COLUMNS

STATIONS = 20
LINES = 2
PROGRAMS = 50
TOOLS_PER_STATION = 10
BOLTS_PER_PART = (4, 8)
NOK_SHARE = 0.015
CONTROLLER_EVERY = 5  # every fifth station is a controller's
#: 2026-01-01 00:00 UTC, in ns: when the synthetic year starts
START_NS = 1_767_225_600 * 1_000_000_000
DAY_NS = 86_400 * 1_000_000_000
ROWS_PER_TRANSACTION = 200_000
HOST = "line-server"
PLANT = "Plant 1"


@dataclass(frozen=True)
class Program:
    program_id: int
    name: str
    torque_nm: float  # nominal; windows ±10 %
    angle_deg: float  # nominal; windows ±15 deg
    force_n: float  # nominal; windows ±5 %


@dataclass
class Station:
    station: str
    line: str
    programs: list[Program]
    tools: list[int]
    controller: bool
    run_id: int = 0
    part_id: str = ""
    bolts_left: int = 0
    program: Program | None = None
    tool_id: int = 0
    bolt: int = 0


@dataclass
class Plant:
    stations: list[Station]
    parts_per_line: dict[str, int] = field(default_factory=dict)


def plant() -> Plant:
    programs = [
        Program(
            p,
            f"M{10 + 2 * (p % 4)} program {p}",
            float(20 + (p * 37) % 280),
            float(30 + (p * 13) % 60),
            float(10_000 + (p * 1_733) % 70_000),
        )
        for p in range(1, PROGRAMS + 1)
    ]
    per_line = STATIONS // LINES
    stations = [
        Station(
            f"st{s + 1:02d}",
            f"L{s // per_line + 1}",
            [program for program in programs if (program.program_id - 1) % STATIONS == s],
            [1000 + TOOLS_PER_STATION * s + j for j in range(TOOLS_PER_STATION)],
            controller=s % CONTROLLER_EVERY == CONTROLLER_EVERY - 1,
        )
        for s in range(STATIONS)
    ]
    return Plant(stations)


@dataclass
class Rows:
    """What a fill wrote."""

    tightenings: int = 0
    steps: int = 0


def synthetic_rows(
    rows: int, days: float, seed: int, made: Rows
) -> Iterator[tuple[tuple[Any, ...], list[tuple[Any, ...]]]]:
    """``rows`` tightenings rows (each with its steps rows) in time order, counted in
    ``made``."""
    rng = random.Random(seed)
    the_plant = plant()
    step_ns = int(days * DAY_NS / rows)
    day_names: dict[int, str] = {}
    for i in range(rows):
        station = the_plant.stations[i % STATIONS]
        if station.bolts_left == 0:
            counter = the_plant.parts_per_line.get(station.line, 0) + 1
            the_plant.parts_per_line[station.line] = counter
            station.part_id = f"{station.line}-P{counter:07d}"
            station.bolts_left = rng.randint(*BOLTS_PER_PART)
            station.program = rng.choice(station.programs)
            station.tool_id = rng.choice(station.tools)
            station.bolt = 0
        station.bolts_left -= 1
        station.bolt += 1
        station.run_id += 1
        ended_ns = START_NS + i * step_ns + rng.randrange(step_ns)
        day = ended_ns // DAY_NS
        if day not in day_names:
            day_names[day] = _day_name(day)
        made.tightenings += 1
        row, steps = _row(station, ended_ns, day_names[day], rng)
        made.steps += len(steps)
        yield row, steps


def _row(
    station: Station, ended_ns: int, day: str, rng: random.Random
) -> tuple[tuple[Any, ...], list[tuple[Any, ...]]]:
    program = station.program
    assert program is not None
    torque = rng.gauss(program.torque_nm, program.torque_nm * 0.025)
    angle = rng.gauss(program.angle_deg, 15.0 / 4)
    force = None if station.controller else rng.gauss(program.force_n, program.force_n * 0.0125)
    if rng.random() < NOK_SHARE:  # one figure out of its window
        pushed = rng.randrange(2 if station.controller else 3)
        side = rng.choice((-1.0, 1.0))
        if pushed == 0:
            torque = program.torque_nm * (1.0 + side * rng.uniform(0.11, 0.2))
        elif pushed == 1:
            angle = program.angle_deg + side * rng.uniform(16.0, 30.0)
        else:
            force = program.force_n * (1.0 + side * rng.uniform(0.06, 0.1))
    judged = (
        ("torque", judge(torque, program.torque_nm * 0.9, program.torque_nm * 1.1), "Nm"),
        ("angle", judge(angle, program.angle_deg - 15.0, program.angle_deg + 15.0), "deg"),
        (
            "preload",
            judge(force, program.force_n * 0.95, program.force_n * 1.05)
            if force is not None
            else judge(None, None, None),
            "N",
        ),
    )
    reasons = [
        f"{name} {figure.status}: {figure.value:g} {unit}, window {figure.min:g} to "
        f"{figure.max:g} {unit}"
        for name, figure, unit in judged
        if figure.status in ("low", "high")
    ]
    t, a, f = (figure for _, figure, _ in judged)
    run_id = station.run_id
    seconds = (ended_ns // 1_000_000_000) % 86_400
    clock = f"{seconds // 3600:02d}{seconds // 60 % 60:02d}{seconds % 60:02d}"
    folder = station.station
    recording = f"/srv/boltwatch/recordings/{folder}/{day}/{folder}_run{run_id}_{clock}.mcap"
    controller = station.controller
    row = (
        station.station, run_id, PLANT, station.line, f"Station {station.station[2:]}",
        run_id + 500_000 if controller else run_id, station.tool_id, program.program_id,
        program.name, station.part_id, station.bolt if controller else None, ended_ns,
        "NOK" if reasons else "OK", "; ".join(reasons),
        t.value, t.min, t.max, t.status, a.value, a.min, a.max, a.status,
        f.value, f.min, f.max, f.status,
        None if controller else "plateau_closest",
        None if controller else rng.randrange(16),
        None if controller else rng.uniform(0.1, 3.0),
        "controller" if controller else "predictor",
        recording, HOST, ended_ns + 200_000_000 + rng.randrange(50_000_000),
    )  # fmt: skip
    steps = _steps(station.station, run_id, program, t) if controller else []
    return row, steps


def _steps(station: str, run_id: int, program: Program, torque: JudgedFigure) -> list[Any]:
    """A controller's 3 steps: the rundown, then two tightening steps to the program's torque."""
    final = "NOK" if torque.status in ("low", "high") else "OK"
    return [
        (station, run_id, 0, "Rundown", "TF Angle", 360.0, 362.0, "OK"),
        (station, run_id, 1, "Tightening 1.1", "TF Torque", program.torque_nm * 0.5,
         program.torque_nm * 0.5, "OK"),
        (station, run_id, 2, "Tightening 1.2", "TF Torque", program.torque_nm, torque.value,
         final),
    ]  # fmt: skip


def _day_name(day: int) -> str:
    from datetime import UTC, datetime

    return datetime.fromtimestamp(day * 86_400, UTC).strftime("%Y-%m-%d")


def fill_sqlite(
    path: Path, rows: int, days: float, seed: int, version: int = SCHEMA_VERSION
) -> Rows:
    """The store at ``path`` (made by ResultsStore, or at an older ``version``) filled with
    :func:`synthetic_rows` (the columns that version has)."""
    columns = _make(StoreTarget(sqlite_path=path), version)
    made = Rows()
    connection = sqlite3.connect(path, isolation_level=None)
    connection.execute("PRAGMA synchronous=OFF")
    connection.execute("PRAGMA cache_size=-1048576")
    insert = _insert("tightenings", columns)
    insert_step = _insert("tightening_steps", STEP_COLUMNS)
    try:
        for chunk, steps in _chunks(synthetic_rows(rows, days, seed, made), columns):
            connection.execute("BEGIN")
            connection.executemany(insert, chunk)
            connection.executemany(insert_step, steps)
            connection.execute("COMMIT")
        connection.execute("PRAGMA wal_checkpoint(TRUNCATE)")
    finally:
        connection.close()
    return made


def fill_postgres(
    url: str, rows: int, days: float, seed: int, version: int = SCHEMA_VERSION
) -> Rows:
    """The store at ``url`` (made by ResultsStore, or at an older ``version``) filled with
    :func:`synthetic_rows` by COPY, then VACUUM ANALYZE."""
    columns = _make(StoreTarget(postgres_url=url), version)
    made = Rows()
    with psycopg.connect(url) as connection:
        for chunk, steps in _chunks(synthetic_rows(rows, days, seed, made), columns):
            with connection.cursor() as cursor:
                _copy(cursor, "tightenings", columns, chunk)
                _copy(cursor, "tightening_steps", STEP_COLUMNS, steps)
            connection.commit()
        connection.autocommit = True
        connection.execute("VACUUM ANALYZE tightenings")
        connection.execute("VACUUM ANALYZE tightening_steps")
    return made


def _copy(
    cursor: psycopg.Cursor[Any], table: str, columns: tuple[str, ...], rows: list[tuple[Any, ...]]
) -> None:
    with cursor.copy(f"COPY {table} ({', '.join(columns)}) FROM STDIN") as copy:
        for row in rows:
            copy.write_row(row)


def _insert(table: str, columns: tuple[str, ...]) -> str:
    return f"INSERT INTO {table} ({', '.join(columns)}) VALUES ({', '.join('?' * len(columns))})"


def _make(target: StoreTarget, version: int) -> tuple[str, ...]:
    """The store at ``version`` (its tables and indexes the product's); its tightenings'
    columns."""
    if version == SCHEMA_VERSION:
        ResultsStore(target).close()
        return TIGHTENING_COLUMNS
    with ResultsDatabase(target) as database:
        migrate(database, MIGRATIONS[:version])
    if version == 1:  # before the plant model
        return tuple(c for c in TIGHTENING_COLUMNS if c not in ("plant", "station_name"))
    assert version == 2, f"no version {version}"  # 3 added a table, no column
    return TIGHTENING_COLUMNS


def _chunks(
    rows: Iterator[tuple[tuple[Any, ...], list[tuple[Any, ...]]]],
    columns: tuple[str, ...] = TIGHTENING_COLUMNS,
) -> Iterator[tuple[list[tuple[Any, ...]], list[tuple[Any, ...]]]]:
    """Rows in transactions of :data:`ROWS_PER_TRANSACTION`, each of ``columns`` only."""
    kept = [TIGHTENING_COLUMNS.index(column) for column in columns]
    whole = columns == TIGHTENING_COLUMNS
    chunk: list[tuple[Any, ...]] = []
    steps: list[tuple[Any, ...]] = []
    for row, row_steps in rows:
        chunk.append(row if whole else tuple(row[i] for i in kept))
        steps.extend(row_steps)
        if len(chunk) == ROWS_PER_TRANSACTION:
            yield chunk, steps
            chunk, steps = [], []
    if chunk:
        yield chunk, steps
