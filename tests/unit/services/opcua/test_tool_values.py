"""A wear ledger's tool as the counters of an IJT tool asset (pure)."""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

from services.opcua.tool_values import tool_counters
from shared.wear import ToolWear, WearLedger, forecast
from shared.wear.wear_tool_data import ControllerTool
from tests.support.wear_plant import TWO_SHIFTS, plant_until, write_ledger

T0_NS = 1_700_000_000_000_000_000


def _wear(controller: ControllerTool | None, service_ns: int | None) -> ToolWear:
    return ToolWear(
        tool_id=7, runs=12, total_intensity=30.0, intensity_per_run=2.5,
        last_service_ns=service_ns, last_service_note=None, runs_since_service=4,
        intensity_since_service=9.5, controller=controller,
    )  # fmt: skip


def test_the_ledgers_counts_and_the_newest_service_of_ledger_and_controller() -> None:
    controller = ControllerTool(
        "st1", "B1234", "C99", 4000, 100, T0_NS - 5, T0_NS - 2, 51.2, "QST", "QST50", "2.1", T0_NS
    )
    counters = tool_counters(_wear(controller, service_ns=T0_NS - 3), threshold=40.0)
    assert (counters.tightenings, counters.tightenings_since_service) == (12, 4)  # the ledger's
    assert (counters.intensity_since_service, counters.intensity_total) == (9.5, 30.0)
    assert counters.intensity_threshold == 40.0
    assert (counters.serial_number, counters.model) == ("B1234", "QST50")
    assert counters.last_service_ns == T0_NS - 2  # the controller's is newer
    assert (counters.last_calibration_ns, counters.calibration_value_nm) == (T0_NS - 5, 51.2)


def test_a_tool_no_controller_spoke_of_has_no_serial_nor_dates() -> None:
    counters = tool_counters(_wear(None, service_ns=None), threshold=None)
    assert (counters.serial_number, counters.model, counters.intensity_threshold) == (
        "",
        None,
        None,
    )
    assert (counters.last_service_ns, counters.last_calibration_ns) == (None, None)


def test_the_lifetime_variable_warns_before_its_limit_and_the_forecast_is_beside_it(
    tmp_path: Path,
) -> None:
    now_ns = time.time_ns()
    plant = plant_until(replace(TWO_SHIFTS, days=35, stations=2, swap_day=None), 3, now_ns)
    write_ledger(plant, tmp_path / "wear.sqlite")
    with WearLedger(tmp_path / "wear.sqlite", read_only=True) as ledger:
        wear = ledger.tool(100)
    assert wear.outlook is not None
    threshold = wear.intensity_since_service + 3 * wear.outlook.pace.per_day
    counters = tool_counters(wear, threshold, now_ns)
    assert counters.intensity_warnings == [0.8 * threshold, 0.95 * threshold]
    told = forecast(
        wear.tool_id,
        wear.outlook.pace,
        wear.outlook.calendar,
        wear.intensity_since_service,
        threshold,
        now_ns,
    )
    assert told.state == "forecast" and told.due_ns is not None
    assert counters.service_due_ns == told.due_ns > now_ns
    assert (counters.service_due_early_ns, counters.service_due_late_ns) == (
        told.early_ns,
        told.late_ns,
    )
    assert told.runs_left is not None and told.runs_left > 0
    assert counters.tightenings_to_service == told.runs_left
    due = tool_counters(wear, wear.intensity_since_service / 2, now_ns)
    assert (due.service_due_ns, due.tightenings_to_service) == (None, 0)
    unset = tool_counters(wear, None, now_ns)
    assert (unset.intensity_warnings, unset.service_due_ns, unset.tightenings_to_service) == (
        None,
        None,
        None,
    )
