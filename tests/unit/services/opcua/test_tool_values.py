"""A wear ledger's tool as the counters of an IJT tool asset (pure)."""

from __future__ import annotations

from services.opcua.tool_values import tool_counters
from shared.wear import ToolWear
from shared.wear.wear_tool_data import ControllerTool

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
