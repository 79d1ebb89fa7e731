"""A line's alerts and a controller's alarms as what IJT's conditions say, pure (no asyncua).

:func:`alert_event` gives, for what ``boltwatch/<st>/wear/alert``, ``quality/alert`` and
``alarms`` carry, the condition it is about (:attr:`AlertEvent.key`, its source and name:
:mod:`.condition_states`), whether the alert is on, and the fields of its
``JoiningSystemConditionType`` event (IJT Base; its ``JoiningSystemEventContent`` with
``EventCode`` and ``EventText``); :func:`wear_cleared` the same for a tool the wear ledger
shows serviced (below its threshold again). The station's conditions report them
(:mod:`.alert_conditions`).

- ``WearAlert``: code 1, ThresholdViolationConditionClassType, severity 500; serviced
  (:func:`wear_cleared`): ThresholdViolationResolvedConditionClassType, severity 100;
- ``QualityAlert``: code 11 (Cpk low), 12 (NOKs in a row), 13 (NOK rate),
  ThresholdViolationConditionClassType and severity 700; cleared (``active``
  False): ThresholdViolationResolvedConditionClassType, severity 100;
- ``ControllerAlarm``: code the ASCII digits of the controller's code (E404: 404;
  0 when it has none), ErrorConditionClassType, severity 800, 100 when it went off.

``EventText`` (and the event's ``Message``) is the alert's own text, with the
controller's code for an alarm; ``JoiningTechnology`` "Tightening".

=========================  ===============================  =================================
alert                      condition (key)                  name
=========================  ===============================  =================================
``WearAlert``              ``wear/<tool id>``               ``Wear of tool <tool id>``
``QualityAlert``           ``quality/<program>/<kind>``     ``Quality of program <p>: <kind>``
``ControllerAlarm``        ``alarm/<code>``                 ``Controller alarm <code>``
=========================  ===============================  =================================
"""

from __future__ import annotations

import string
from dataclasses import dataclass

from services.opcua.condition_states import Source
from shared.contract import ControllerAlarm, QualityAlert, WearAlert

#: IJT Base condition classes (numeric ids in its namespace) and their names
THRESHOLD_VIOLATION = (1033, "ThresholdViolationConditionClassType")
THRESHOLD_VIOLATION_RESOLVED = (1036, "ThresholdViolationResolvedConditionClassType")
ERROR_CONDITION = (1063, "ErrorConditionClassType")
#: EventCode of boltwatch's own alerts
WEAR_CODE = 1
WEAR_SEVERITY = 500
#: the severity of an alert gone off
CLEARED_SEVERITY = 100
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
    key: str  # the condition's key: "wear/7", "quality/1/nok_run", "alarm/E404"
    source: Source
    name: str  # ConditionName
    active: bool  # the alert is on (False: it went off)


def alert_event(alert: Alert) -> AlertEvent:
    if isinstance(alert, WearAlert):
        text = (
            f"tool {alert.tool_id}: stick-slip intensity since service "
            f"{alert.intensity_since_service:.1f} reached its threshold {alert.threshold:g} "
            f"({alert.runs_since_service} tightenings since service)"
        )
        return AlertEvent(
            alert.station,
            alert.time_ns,
            WEAR_CODE,
            text,
            WEAR_SEVERITY,
            THRESHOLD_VIOLATION,
            f"wear/{alert.tool_id}",
            "wear",
            wear_condition_name(alert.tool_id),
            True,
        )
    if isinstance(alert, QualityAlert):
        if alert.active:
            severity, condition = 700, THRESHOLD_VIOLATION
        else:
            severity, condition = CLEARED_SEVERITY, THRESHOLD_VIOLATION_RESOLVED
        return AlertEvent(
            alert.station,
            alert.time_ns,
            QUALITY_CODES[alert.kind],
            alert.text,
            severity,
            condition,
            f"quality/{alert.program_id}/{alert.kind}",
            "quality",
            f"Quality of program {alert.program_id}: {alert.kind}",
            alert.active,
        )
    digits = "".join(character for character in alert.error_code if character in string.digits)
    state = "" if alert.active else " (off)"
    text = f"{alert.error_code}{state}: {alert.text}" if alert.text else alert.error_code + state
    return AlertEvent(
        alert.station,
        alert.time_ns,
        int(digits) if digits and len(digits) < 19 else 0,  # an Int64
        text,
        800 if alert.active else CLEARED_SEVERITY,
        ERROR_CONDITION,
        f"alarm/{alert.error_code}",
        "alarm",
        f"Controller alarm {alert.error_code}",
        alert.active,
    )


def wear_condition_name(tool_id: int) -> str:
    return f"Wear of tool {tool_id}"


def wear_cleared(
    station: str, tool_id: int, time_ns: int, intensity_since_service: float, threshold: float
) -> AlertEvent:
    """A tool's wear condition gone off: the ledger shows it below its threshold (serviced)."""
    text = (
        f"tool {tool_id}: stick-slip intensity since service {intensity_since_service:.1f} "
        f"below its threshold {threshold:g} (serviced)"
    )
    return AlertEvent(
        station,
        time_ns,
        WEAR_CODE,
        text,
        CLEARED_SEVERITY,
        THRESHOLD_VIOLATION_RESOLVED,
        f"wear/{tool_id}",
        "wear",
        wear_condition_name(tool_id),
        False,
    )
