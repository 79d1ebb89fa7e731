"""A line's alerts and a controller's alarms as IJT joining system events, pure (no asyncua).

:func:`alert_event` gives the fields of a ``JoiningSystemEventType`` event (IJT
Base; its ``JoiningSystemEventContent`` with ``EventCode`` and ``EventText``)
for what ``boltwatch/<st>/wear/alert``, ``quality/alert`` and ``alarms`` carry;
the joining system emits it (:meth:`~.joining_systems.JoiningSystem.report`).

- ``WearAlert``: code 1, ThresholdViolationConditionClassType, severity 500;
- ``QualityAlert``: code 11 (Cpk low), 12 (NOKs in a row), 13 (NOK rate),
  ThresholdViolationConditionClassType and severity 700; cleared (``active``
  False): ThresholdViolationResolvedConditionClassType, severity 100;
- ``ControllerAlarm``: code the ASCII digits of the controller's code (E404: 404;
  0 when it has none), ErrorConditionClassType, severity 800, 100 when it went off.

``EventText`` (and the event's ``Message``) is the alert's own text, with the
controller's code for an alarm; ``JoiningTechnology`` "Tightening".
"""

from __future__ import annotations

import string
from dataclasses import dataclass

from shared.contract import ControllerAlarm, QualityAlert, WearAlert

#: IJT Base condition classes (numeric ids in its namespace) and their names
THRESHOLD_VIOLATION = (1033, "ThresholdViolationConditionClassType")
THRESHOLD_VIOLATION_RESOLVED = (1036, "ThresholdViolationResolvedConditionClassType")
ERROR_CONDITION = (1063, "ErrorConditionClassType")
#: EventCode of boltwatch's own alerts
WEAR_CODE = 1
QUALITY_CODES = {"cpk_low": 11, "nok_run": 12, "nok_rate": 13}

Alert = WearAlert | QualityAlert | ControllerAlarm


@dataclass(frozen=True, slots=True)
class AlertEvent:
    station: str
    time_ns: int
    code: int  # JoiningSystemEventContent/EventCode
    text: str  # JoiningSystemEventContent/EventText, and the event's Message
    severity: int  # 1 to 1000
    condition_class: tuple[int, str]  # ConditionClassId (IJT Base) and ConditionClassName


def alert_event(alert: Alert) -> AlertEvent:
    if isinstance(alert, WearAlert):
        text = (
            f"tool {alert.tool_id}: stick-slip intensity since service "
            f"{alert.intensity_since_service:.1f} reached its threshold {alert.threshold:g} "
            f"({alert.runs_since_service} tightenings since service)"
        )
        return AlertEvent(alert.station, alert.time_ns, WEAR_CODE, text, 500, THRESHOLD_VIOLATION)
    if isinstance(alert, QualityAlert):
        if alert.active:
            severity, condition = 700, THRESHOLD_VIOLATION
        else:
            severity, condition = 100, THRESHOLD_VIOLATION_RESOLVED
        return AlertEvent(
            alert.station,
            alert.time_ns,
            QUALITY_CODES[alert.kind],
            alert.text,
            severity,
            condition,
        )
    digits = "".join(character for character in alert.error_code if character in string.digits)
    state = "" if alert.active else " (off)"
    text = f"{alert.error_code}{state}: {alert.text}" if alert.text else alert.error_code + state
    return AlertEvent(
        alert.station,
        alert.time_ns,
        int(digits) if digits and len(digits) < 19 else 0,  # an Int64
        text,
        800 if alert.active else 100,
        ERROR_CONDITION,
    )
