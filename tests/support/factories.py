"""Messages for tests, each with plausible values that a test changes by keyword.

One factory a message type: what names the message is positional (the run id,
a sample's sequence, an event's index), every other field a keyword change
(``summary(4, process_intensity=2.5)``). The defaults are one run of program 1
of the shipped station (``config/station.toml``), ended at :data:`T0`: 3 s,
2500 samples, 9 events, stopped by the predictor at the plateau closest to
56 kN, OK against the program's windows. A test passes every value its
assertions rely on, even one equal to a default.
"""

from __future__ import annotations

from typing import Any

from shared.config import Program
from shared.contract import (
    JudgedFigure,
    PartScan,
    RunSummary,
    Sample,
    StickSlipEvent,
    TighteningResult,
)

#: a second, in ns
S = 1_000_000_000

#: a millisecond, in ns: a sample's period at 1 kHz
MS = 1_000_000

#: the tests' wall clock (2023-11-14 22:13:20 UTC), in ns: when the default run ended
T0 = 1_700_000_000 * S


def summary(run_id: int, **changes: Any) -> RunSummary:
    """The RunSummary of run ``run_id``: tool 7, program 1, done at :data:`T0` after 3 s."""
    fields: dict[str, Any] = {
        "station": "st1",
        "run_id": run_id,
        "tool_id": 7,
        "program_id": 1,
        "tool_state": "done",
        "target_force_n": 56000.0,
        "target_torque_nm": 200.0,
        "reached_force_n": 55800.0,
        "reached_torque_nm": 190.0,
        "error_pct": -0.357,
        "events": 9,
        "stop_reason": "plateau_closest",
        "process_intensity": 0.4,
        "samples": 2500,
        "started_ns": T0 - 3 * S,
        "ended_ns": T0,
    }
    fields.update(changes)
    return RunSummary(**fields)


def sample(run_id: int, sequence: int, **changes: Any) -> Sample:
    """Sample ``sequence`` of run ``run_id`` at 1 kHz from :data:`T0`: 10 Nm, 1 deg, 20 kN."""
    fields: dict[str, Any] = {
        "station": "st1",
        "run_id": run_id,
        "sequence": sequence,
        "time_ns": T0 + sequence * MS,
        "torque_nm": 10.0,
        "angle_deg": 1.0,
        "force_n": 20_000.0,
    }
    fields.update(changes)
    return Sample(**fields)


def event(run_id: int, index: int, **changes: Any) -> StickSlipEvent:
    """Stick-slip event ``index`` (from 1) of run ``run_id``, ``index`` ms after :data:`T0`:
    a 5 Nm slip from 50 Nm at 20 kN, every figure of eqs. 31-33 and 66-68 given, no
    prediction."""
    fields: dict[str, Any] = {
        "station": "st1",
        "run_id": run_id,
        "index": index,
        "time_ns": T0 + index * MS,
        "time_s": 0.1,
        "peak_torque_nm": 50.0,
        "min_torque_nm": 45.0,
        "torque_drop_nm": 5.0,
        "plateau_force_n": 20_000.0,
        "force_step_n": 100.0,
        "period_s": 0.02,
        "f_ss_hz": 50.0,
        "k1": 1.0,
        "k2": 2.0,
        "k3": 3.0,
        "intensity": 0.5,
        "process_intensity": 0.5 * index,
        "predictions": [],
    }
    fields.update(changes)
    return StickSlipEvent(**fields)


def result(run_id: int, **changes: Any) -> TighteningResult:
    """The predictor's TighteningResult of run ``run_id`` (the default :func:`summary`'s run):
    OK in program 1's windows (preload 53 to 59 kN, torque 180 to 240 Nm, angle 35 to 65 deg)."""
    fields: dict[str, Any] = {
        "station": "st1",
        "tightening_id": run_id,
        "run_id": run_id,
        "tool_id": 7,
        "program_id": 1,
        "program_name": "M14 to 56 kN",
        "time_ns": T0,
        "part_id": None,
        "batch_counter": None,
        "final_torque_nm": JudgedFigure(190.0, 180.0, 240.0, "ok"),
        "final_angle_deg": JudgedFigure(50.0, 35.0, 65.0, "ok"),
        "final_force_n": JudgedFigure(55800.0, 53000.0, 59000.0, "ok"),
        "result": "OK",
        "nok_reasons": "",
        "stop_reason": "plateau_closest",
        "events": 9,
        "process_intensity": 0.4,
        "source": "predictor",
    }
    fields.update(changes)
    return TighteningResult(**fields)


def part_scan(part_id: str, **changes: Any) -> PartScan:
    """The line's scan of part ``part_id`` at st1, 10 s before :data:`T0` (before the default
    run started)."""
    fields: dict[str, Any] = {"station": "st1", "part_id": part_id, "time_ns": T0 - 10 * S}
    fields.update(changes)
    return PartScan(**fields)


def program(**changes: Any) -> Program:
    """Program 1 of the shipped station without its windows (a change adds them): 56 kN (or
    200 Nm) from 10 kN at 0.5 rad/s, hard limits 320 Nm, 75 kN, 150 deg, 6 s."""
    fields: dict[str, Any] = {
        "id": 1,
        "name": "M14 to 56 kN",
        "target_force_n": 56000.0,
        "target_torque_nm": 200.0,
        "motor_speed_rad_s": 0.5,
        "start_force_n": 10000.0,
        "max_torque_nm": 320.0,
        "max_force_n": 75000.0,
        "max_angle_deg": 150.0,
        "max_time_s": 6.0,
    }
    fields.update(changes)
    return Program(**fields)
