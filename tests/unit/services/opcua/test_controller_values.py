"""A station's controller as the identification of an IJT controller asset (pure)."""

from __future__ import annotations

from services.opcua.controller_values import (
    BOLTWATCH,
    CAN_MODEL,
    JOINING_PROCESS_CONTROLLER,
    ControllerIdentity,
    controller_identity,
)
from shared.wear import ToolWear
from shared.wear.wear_tool_data import ControllerTool

T0_NS = 1_700_000_000_000_000_000


def _wear(tool_id: int, controller: ControllerTool | None) -> ToolWear:
    return ToolWear(
        tool_id=tool_id, runs=12, total_intensity=30.0, intensity_per_run=2.5,
        last_service_ns=None, last_service_note=None, runs_since_service=4,
        intensity_since_service=9.5, controller=controller,
    )  # fmt: skip


def _said(controller_serial: str | None, software: str | None, received_ns: int) -> ControllerTool:
    return ControllerTool(
        "st1", "B1234", controller_serial, 4000, 100, None, None, None, None, None, software,
        received_ns,
    )  # fmt: skip


def test_a_can_stations_controller_is_boltwatchs_acquisition() -> None:
    identity = controller_identity(False, [_wear(7, None)], "1.2.3")
    assert identity == ControllerIdentity("", "1.2.3", BOLTWATCH, CAN_MODEL)
    assert identity.kind == JOINING_PROCESS_CONTROLLER


def test_a_controller_stations_controller_is_what_it_said_last_of_itself() -> None:
    tools = [
        _wear(1, _said("C-OLD", "1.0", T0_NS)),
        _wear(2, None),
        _wear(3, _said("C-NEW", None, T0_NS + 5)),  # newest: no software said
    ]
    assert controller_identity(True, tools, "1.2.3") == ControllerIdentity("C-NEW", "", None, None)


def test_a_controller_that_said_nothing_yet_is_not_known() -> None:
    assert controller_identity(True, [_wear(1, None)], "1.2.3") == ControllerIdentity(
        "", "", None, None
    )
