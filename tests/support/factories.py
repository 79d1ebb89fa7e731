"""Messages for tests, each with plausible values that a test changes by keyword."""

from __future__ import annotations

from typing import Any

from shared.contract import (
    RunSummary,
)

S = 1_000_000_000


T0 = 1_700_000_000 * S


def summary(run_id: int, **changes: Any) -> RunSummary:
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
