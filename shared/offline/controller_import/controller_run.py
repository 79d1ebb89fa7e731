"""One tightening run as a Bosch Rexroth CS351 controller exports it (JSON), read strictly.

The ``graph`` of each entry of ``tightening steps`` is concatenated in order,
keeping the controller's own timing: repeated timestamps and gaps of tens of
milliseconds stay as they are (about 833 Hz, torque and angle only, no
preload). The run's identity comes from the file's header: ``cycle`` (the
run id, as in the dataset's labels), ``tool serial``, ``prg nr``, ``date``
(controller local time, no zone in the file: taken as UTC). Other controllers
of the family write the same layout with identifiers as text (``"tool
serial": "520000905"``): an identifier is an integer from 0 up, written as a
number or as its digits; a serial that is no such number (``"GP1010003"``)
cannot be a tool id of the wear ledger and is refused, naming the key. The
serial as written is kept in the ``controller`` metadata record.

What the run did: a **loosening** when every step that says its ``speed``
turns the tool back (a negative speed), else a tightening
(:func:`~shared.offline.controller_import.controller_steps.run_operation`).

The torque's **resolution** (:attr:`ControllerRun.torque_resolution_nm`): the
smallest step between two of the run's torque values, what the controller
writes (0.001 Nm for the CS351 runs at hand); a drop the signal cannot
resolve is no stick-slip event (:mod:`shared.stickslip.extremum_tracker`).

The controller's own result (each step's name, OK/NOK, nominal and actual
values, the run's verdict, part and batch) is read too
(:mod:`shared.offline.controller_import.controller_steps`), and the clock is checked
(:mod:`shared.offline.controller_import.controller_timing`: representable, never going back).

Anything unusable (a cut file, a wrong type, a missing field, a number that
is not finite, a run id below 0, a clock that goes back) is one
:class:`~shared.errors.InputError` naming the file and the key.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, replace
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from shared.contract import ControllerResult, ControllerStep, RunClock, RunOperation
from shared.errors import InputError
from shared.offline.controller_import.controller_steps import (
    ControllerVerdict,
    integer_expected,
    integer_of,
    read_speed,
    read_step,
    read_verdict,
    run_operation,
    text,
    torque_function,
)
from shared.offline.controller_import.controller_timing import check_date, check_times
from shared.stickslip import signal_resolution

STEPS_KEY = "tightening steps"
TIME_KEY, TORQUE_KEY, ANGLE_KEY = "time values", "torque values", "angle values"
DATE_FORMAT = "%Y-%m-%d %H:%M:%S"
#: Identity fields are integers from 0 up to what the wear ledger (SQLite) holds.
LARGEST_ID = 2**63 - 1

#: Header fields kept in the ``controller`` metadata record of an imported run.
HEADER_FIELDS = (
    "tool serial",
    "hardware",
    "sw version",
    "node id",
    "prg name",
    "prg date",
    "nominal torque",
    "torque unit",
    "result",
    "quality code",
    "id code",
    "last cmd",
    "total time",
)


@dataclass(frozen=True)
class ControllerRun:
    """One controller run: identity, header, the concatenated graph, the controller's result."""

    source: Path
    run_id: int  # ``cycle``
    tool_id: int  # ``tool serial``
    program_id: int  # ``prg nr``
    date_ns: int  # ``date``, taken as UTC; ``time values`` count from it
    header: dict[str, str]
    time_s: list[float]  # the controller's ``time values``: s since ``date``
    torque_nm: list[float]
    angle_deg: list[float]
    steps: list[ControllerStep]
    verdict: ControllerVerdict
    operation: RunOperation = "tightening"

    def __len__(self) -> int:
        return len(self.time_s)

    @property
    def step_names(self) -> list[str]:
        return [step.name for step in self.steps]

    @property
    def times_ns(self) -> list[int]:
        """Each sample's time: ``date`` + its time value, in integer nanoseconds."""
        return RunClock(self.date_ns).ns_of(self.time_s)

    @property
    def ended_ns(self) -> int:
        """When the run ended: one nanosecond after its last sample (``ToolState`` done)."""
        return self.times_ns[-1] + 1

    @property
    def started_ns(self) -> int:
        """The run starts at its first sample (``ToolState`` running, the file's name)."""
        return RunClock(self.date_ns).ns(self.time_s[0])

    @property
    def run_time_s(self) -> list[float]:
        """Each sample's time since the run's first sample (trace CSVs, the predictor)."""
        first = self.time_s[0]
        return [t - first for t in self.time_s]

    @property
    def torque_resolution_nm(self) -> float:
        """The smallest step between two of the run's torque values (0: none seen)."""
        return signal_resolution(self.torque_nm)

    @property
    def final_torque_nominal_nm(self) -> float | None:
        """The last step's ``TF Torque`` nominal: the torque the run was meant to end at."""
        function = torque_function(self.steps[-1])
        return None if function is None else function.nominal

    @property
    def final_torque_actual_nm(self) -> float | None:
        """The last step's ``TF Torque`` actual: the torque the controller reached."""
        function = torque_function(self.steps[-1])
        return None if function is None else function.actual

    def result(self, station: str, time_ns: int) -> ControllerResult:
        """The controller's result of this run as the message recorded on ``controller``."""
        verdict = self.verdict
        return ControllerResult(
            station=station,
            run_id=self.run_id,
            tool_id=self.tool_id,
            program_id=self.program_id,
            time_ns=time_ns,
            result=verdict.result,
            quality_code=verdict.quality_code,
            part_id=verdict.part_id,
            torque_unit=verdict.torque_unit,
            torsion_release_samples=verdict.torsion_release_samples,
            steps=list(self.steps),
            operation=self.operation,
            **verdict.batch,
        )


def read_controller_run(path: Path) -> ControllerRun:
    """The run of one controller JSON file; InputError naming the file if unusable."""
    document = _load(path)
    if not isinstance(document, dict):
        raise InputError(f"{path}: expected a JSON object (a CS351 run), got {_kind(document)}")
    steps = document.get(STEPS_KEY)
    if not isinstance(steps, list) or not steps:
        raise InputError(f"{path}: no '{STEPS_KEY}' list: not a CS351 controller run")
    run_id = _integer(path, document, "cycle")
    tool_id = _integer(path, document, "tool serial")
    program_id = _integer(path, document, "prg nr")
    date_ns = _date_ns(path, document)
    columns: tuple[list[float], list[float], list[float]] = ([], [], [])
    step_times: list[list[float]] = []
    step_records: list[ControllerStep] = []
    speeds: list[float | None] = []
    for number, step in enumerate(steps):
        times, torques, angles = _step_columns(path, number, step)
        speeds.append(read_speed(path, f"{STEPS_KEY}[{number}]", step))
        columns[0].extend(times)
        columns[1].extend(torques)
        columns[2].extend(angles)
        step_times.append(times)
        step_records.append(read_step(path, f"{STEPS_KEY}[{number}]", step, len(times)))
        if not step_records[-1].name:
            step_records[-1] = replace(step_records[-1], name=f"step {number}")
    if not columns[0]:
        raise InputError(f"{path}: the tightening steps hold no samples")
    check_times(path, date_ns, step_times, STEPS_KEY)
    last = len(steps) - 1
    verdict = read_verdict(path, document, steps[last]["graph"], f"{STEPS_KEY}[{last}].graph")
    return ControllerRun(
        source=path,
        run_id=run_id,
        tool_id=tool_id,
        program_id=program_id,
        date_ns=date_ns,
        header={name: text(document.get(name)) for name in HEADER_FIELDS},
        time_s=columns[0],
        torque_nm=columns[1],
        angle_deg=columns[2],
        steps=step_records,
        verdict=verdict,
        operation=run_operation(speeds),
    )


def _load(path: Path) -> Any:
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError as err:
        raise InputError(f"{path}: file not found") from err
    except UnicodeDecodeError as err:
        raise InputError(f"{path}: not a text file ({err.reason})") from err
    except json.JSONDecodeError as err:
        raise InputError(
            f"{path}: line {err.lineno} column {err.colno}: not valid JSON "
            f"(truncated or corrupt?): {err.msg}"
        ) from err
    except OSError as err:
        raise InputError(f"{path}: cannot be read: {err.strerror}") from err


def _step_columns(
    path: Path, number: int, step: Any
) -> tuple[list[float], list[float], list[float]]:
    where = f"{path}: {STEPS_KEY}[{number}]"
    graph = step.get("graph") if isinstance(step, dict) else None
    if not isinstance(graph, dict):
        raise InputError(f"{where}: no 'graph' object")
    columns = [_numbers(f"{where}.graph", graph, key) for key in (TIME_KEY, TORQUE_KEY, ANGLE_KEY)]
    lengths = {len(column) for column in columns}
    if len(lengths) != 1:
        counts = ", ".join(
            f"{len(c)} {k}" for c, k in zip(columns, (TIME_KEY, TORQUE_KEY, ANGLE_KEY), strict=True)
        )
        raise InputError(f"{where}.graph: the lists differ in length ({counts})")
    return columns[0], columns[1], columns[2]


def _numbers(where: str, graph: dict[str, Any], key: str) -> list[float]:
    values = graph.get(key)
    if not isinstance(values, list):
        raise InputError(f"{where}: no '{key}' list (found {_kind(values)})")
    out: list[float] = []
    for index, value in enumerate(values):
        if (
            isinstance(value, bool)
            or not isinstance(value, int | float)
            or not math.isfinite(value)
        ):
            raise InputError(f"{where}.{key}[{index}]: expected a finite number, got {value!r}")
        out.append(float(value))
    return out


def _integer(path: Path, document: dict[str, Any], key: str) -> int:
    written = document.get(key)
    value = integer_of(written)
    if value is None:
        raise InputError(f"{path}: '{key}': {integer_expected(written)}")
    if value < 0:
        raise InputError(f"{path}: '{key}': expected a number from 0 up, got {value}")
    if value > LARGEST_ID:
        raise InputError(f"{path}: '{key}': {value} is too large (at most 2**63 - 1)")
    return value


def _date_ns(path: Path, document: dict[str, Any]) -> int:
    value = document.get("date")
    try:
        started = datetime.strptime(str(value), DATE_FORMAT).replace(tzinfo=UTC)
    except ValueError as err:
        raise InputError(
            f"{path}: 'date': expected 'YYYY-MM-DD HH:MM:SS', got {_kind(value)} {value!r}"
        ) from err
    return check_date(path, started)


def _kind(value: Any) -> str:
    return "nothing" if value is None else type(value).__name__
