"""Alerts and a controller's alarms as IJT joining system events (pure)."""

from __future__ import annotations

from services.opcua.alert_events import (
    ERROR_CONDITION,
    THRESHOLD_VIOLATION,
    THRESHOLD_VIOLATION_RESOLVED,
    alert_event,
    wear_cleared,
)
from shared.contract import ControllerAlarm, QualityAlert, WearAlert

T0_NS = 1_700_000_000_000_000_000


def test_a_wear_alert_is_a_threshold_violation_naming_its_tool() -> None:
    event = alert_event(WearAlert("st1", 7, T0_NS, 512.3, 500.0, 88, None))
    assert (event.code, event.severity, event.condition_class) == (1, 500, THRESHOLD_VIOLATION)
    assert event.text == (
        "tool 7: stick-slip intensity since service 512.3 reached its threshold 500 "
        "(88 tightenings since service)"
    )


def test_a_quality_alert_and_its_clearing() -> None:
    def alert(active: bool, text: str) -> QualityAlert:
        return QualityAlert("st1", 1, T0_NS, "nok_run", None, 3.0, 3.0, 3, active, text)

    raised = alert_event(alert(True, "3 NOK in a row"))
    cleared = alert_event(alert(False, "back in control"))
    assert (raised.code, raised.severity, raised.condition_class) == (12, 700, THRESHOLD_VIOLATION)
    assert (cleared.severity, cleared.condition_class) == (100, THRESHOLD_VIOLATION_RESOLVED)
    assert (raised.text, cleared.text) == ("3 NOK in a row", "back in control")


def test_a_controller_alarm_keeps_its_code_and_says_when_it_went_off() -> None:
    def alarm(code: str, active: bool, text: str) -> ControllerAlarm:
        return ControllerAlarm("st1", T0_NS, T0_NS, code, "status", active, None, None, text)

    on = alert_event(alarm("E404", True, "tool not connected"))
    assert (on.code, on.text, on.severity, on.condition_class) == (
        404, "E404: tool not connected", 800, ERROR_CONDITION
    )  # fmt: skip
    off = alert_event(alarm("E404", False, ""))
    assert (off.text, off.severity) == ("E404 (off)", 100)
    assert alert_event(alarm("EBATT", True, "")).code == 0  # no digits in the code
    # only ASCII digits: "²" and "٣" are digits to str.isdigit, and int() refuses "²"
    assert alert_event(alarm("E²٣4", True, "")).code == 4


def test_each_alert_source_is_one_condition() -> None:
    """A tool's wear alerts are one condition, a program's quality alerts one per kind, a
    controller's alarms one per code; each says whether the alert is on."""
    wear = alert_event(WearAlert("st1", 7, T0_NS, 512.3, 500.0, 88, None))
    assert (wear.key, wear.source, wear.name, wear.active) == (
        "wear/7",
        "wear",
        "Wear of tool 7",
        True,
    )
    serviced = wear_cleared("st1", 7, T0_NS, 0.0, 500.0)
    assert (serviced.key, serviced.active, serviced.severity) == ("wear/7", False, 100)
    assert serviced.condition_class == THRESHOLD_VIOLATION_RESOLVED
    quality = alert_event(
        QualityAlert("st1", 2, T0_NS, "cpk_low", "torque", 0.9, 1.33, 25, False, "")
    )
    assert (quality.key, quality.name, quality.active) == (
        "quality/2/cpk_low", "Quality of program 2: cpk_low", False
    )  # fmt: skip
    alarm = alert_event(
        ControllerAlarm("st1", T0_NS, T0_NS, "E404", "status", True, None, None, "")
    )
    assert (alarm.key, alarm.source, alarm.active) == ("alarm/E404", "alarm", True)
