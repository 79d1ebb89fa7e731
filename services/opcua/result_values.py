"""A TighteningResult as the field values of an IJT result, pure (no asyncua, no zenoh).

:func:`result_values` gives the fields of Machinery/Result's ``ResultDataType``
as IJT fills it: ``ResultMetaData`` (a ``JoiningResultMetaDataType``) and one
``JoiningResultDataType`` in ``ResultContent`` with its ``OverallResultValues``
(``ResultValueDataType``). Field names are the specification's; a field whose
value is unknown is left out (they are optional). :mod:`.result_encoding` turns
the dict into asyncua's classes.

What goes where (OPC 40450-1, section 10):

==============================  ==================================================
TighteningResult                IJT field
==============================  ==================================================
``station``/``run_id``          ``ResultId`` ``"<station>/<run id>"`` (the results
                                store's key of a tightening)
``tightening_id``               ``SequenceNumber``
``time_ns``                     ``CreationTime``
``part_id``                     ``PartId``
``program_id``/``program_name``  ``InternalRecipeId`` / ``Name``
``result``, ``nok_reasons``     ``ResultEvaluation`` (OK 1, NotOK 2),
                                ``ResultEvaluationDetails``
final torque, angle, preload    ``OverallResultValues``: ``MeasuredValue``, window
                                as ``LowLimit``/``HighLimit``, its
                                ``ResultEvaluation``, ``PhysicalQuantity`` (TORQUE
                                2, ANGLE 3, FORCE 8) and ``EngineeringUnits``
                                (UNECE N·m, degree, N); a figure not measured is
                                not listed
``events``, ``process_intensity``  two more ``OverallResultValues``: NUMBER (20),
                                and OTHER (0) without unit (eq. 68 of the paper)
``stop_reason``, ``source``,    ``ExtendedMetaData`` (key, text)
``station``, ``tool_id``,
``run_id``
``steps`` (a controller's)      ``StepResults``: per step its ``StepResultId``
                                ``<ResultId>/step/<n>`` (n from 1), ``ProgramStep``
                                n, ``Name``, ``ResultEvaluation``, and one
                                ``StepResultValues`` (``Name`` the step's
                                function, ``MeasuredValue`` its actual,
                                ``TargetValue`` its nominal; no unit: the
                                controller's own) when it has an actual value
a trace (:mod:`.result_trace`)  ``Trace`` (a ``JoiningTraceDataType``): only in a
                                result asked by id, never in the event
==============================  ==================================================

A multi-spindle station's tightening (``spindle`` set) is a single result too, with
its spindle in ``ResultCounters`` (a ``ResultCounterDataType`` of ``CounterType``
SPINDLE_NUMBER, 7) and its cycle's ``sync_id`` as ``ExtendedMetaData`` ``SyncId``;
the cycle's common result is a result of its own (:mod:`.cycle_values`). A
single-spindle station's result has neither.

``Classification`` is 1 (a single result) and ``ResultState`` 1 (completed): a
run that the tool aborted is still a completed result, NOK.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from typing import Any

from shared.contract import INT64_MAX, JudgedFigure, ResultStep, TighteningResult

#: JoiningResultMetaDataType.Classification of one tightening's result
CLASSIFICATION_SINGLE = 1
#: ResultCounterDataType.CounterType (OPC 40450-1, 10.11): the spindle's number in a
#: fixtured system of several spindles
COUNTER_SPINDLE_NUMBER = 7
#: ResultMetaDataType.ResultState: processing was carried out completely
RESULT_STATE_COMPLETED = 1
#: ResultEvaluationEnum (Machinery/Result)
EVALUATION_OK = 1
EVALUATION_NOT_OK = 2
EVALUATION_NOT_DECIDABLE = 3
#: ResultValueDataType.PhysicalQuantity (IJT Base, the EnumStrings of PhysicalQuantity)
QUANTITY_OTHER = 0
QUANTITY_TIME = 1
QUANTITY_TORQUE = 2
QUANTITY_ANGLE = 3
QUANTITY_FORCE = 8
QUANTITY_NUMBER = 20
JOINING_TECHNOLOGY = "Tightening"

#: the UNECE codes' namespace of EUInformation (OPC 10000-8)
UNECE_NAMESPACE = "http://www.opcfoundation.org/UA/units/un/cefact"


@dataclass(frozen=True, slots=True)
class EngineeringUnit:
    """One EUInformation: its UNECE code, the UnitId OPC 10000-8 derives from it, and how
    it reads."""

    unece_code: str
    display_name: str
    description: str

    @property
    def unit_id(self) -> int:
        """OPC 10000-8, 5.6.3: the code's characters, 8 bits each, the first the highest."""
        unit_id = 0
        for character in self.unece_code:
            unit_id = (unit_id << 8) | ord(character)
        return unit_id


NEWTON_METRE = EngineeringUnit("NU", "N·m", "newton metre")
DEGREE = EngineeringUnit("DD", "°", "degree [unit of angle]")
NEWTON = EngineeringUnit("NEW", "N", "newton")
MILLISECOND = EngineeringUnit("C26", "ms", "millisecond")

_EVALUATION_OF_STATUS = {
    "ok": EVALUATION_OK,
    "low": EVALUATION_NOT_OK,
    "high": EVALUATION_NOT_OK,
    "not_judged": EVALUATION_NOT_DECIDABLE,
}
_EVALUATION_OF_STEP = {
    "OK": EVALUATION_OK,
    "NOK": EVALUATION_NOT_OK,
    "not_judged": EVALUATION_NOT_DECIDABLE,
}


EPOCH = datetime(1970, 1, 1, tzinfo=UTC)
_ID = re.compile(r"0|[1-9][0-9]*")
_ID_DIGITS = len(str(INT64_MAX))


def utc_time(time_ns: int) -> datetime:
    """An OPC UA UtcTime (a DateTime) of nanoseconds since the epoch: its whole microseconds,
    exactly (a datetime holds no finer; through a float they would be off by one at times,
    and a filter on CreationTime compares them with the results store's nanoseconds)."""
    return EPOCH + timedelta(microseconds=time_ns // 1000)


def result_id(station: str, run_id: int) -> str:
    """The ResultId of a station's run (unique in the results store)."""
    return f"{station}/{run_id}"


def parse_id(text: str) -> int | None:
    """The run or program id ``text`` is as the server writes one (``str(id)``: ASCII digits,
    no sign, no leading zero, at most :data:`~shared.contract.INT64_MAX`); None for any other
    text, which no result has."""
    if len(text) > _ID_DIGITS or _ID.fullmatch(text) is None or int(text) > INT64_MAX:
        return None  # the length first: int() refuses more than 4300 digits
    return int(text)


def parse_result_id(text: str) -> tuple[str, int] | None:
    """The station and run id of the ResultId ``text`` (what :func:`result_id` gives); None
    for a text it never gives."""
    station, _, run = text.rpartition("/")
    run_id = parse_id(run)
    return None if not station or run_id is None else (station, run_id)


def spindle_counters(spindle: int) -> list[dict[str, Any]]:
    """The ``ResultCounters`` of a spindle's result: its SPINDLE_NUMBER."""
    return [{"Name": "Spindle", "CounterValue": spindle, "CounterType": COUNTER_SPINDLE_NUMBER}]


def result_values(result: TighteningResult, trace: dict[str, Any] | None = None) -> dict[str, Any]:
    """``{"ResultMetaData": {...}, "ResultContent": [{"OverallResultValues": [...], ...}]}``;
    ``trace``: the fields of its ``JoiningTraceDataType`` (:func:`.result_trace.trace_values`)."""
    extended = {
        "Station": result.station,
        "ToolId": str(result.tool_id),
        "RunId": str(result.run_id),
        "Source": result.source,
        "StopReason": result.stop_reason or "tool",
    }
    meta: dict[str, Any] = {
        "ResultId": result_id(result.station, result.run_id),
        "CreationTime": utc_time(result.time_ns),
        "InternalRecipeId": str(result.program_id),
        "ResultState": RESULT_STATE_COMPLETED,
        "ResultEvaluation": EVALUATION_OK if result.result == "OK" else EVALUATION_NOT_OK,
        "JoiningTechnology": JOINING_TECHNOLOGY,
        "SequenceNumber": result.tightening_id,
        "Classification": CLASSIFICATION_SINGLE,
        "ExtendedMetaData": extended,
    }
    if result.part_id is not None:
        meta["PartId"] = result.part_id
    if result.spindle is not None:  # a multi-spindle station's: its spindle, and its cycle
        meta["ResultCounters"] = spindle_counters(result.spindle)
    if result.sync_id is not None:
        extended["SyncId"] = str(result.sync_id)
    if result.program_name:
        meta["Name"] = result.program_name
    if result.nok_reasons:
        meta["ResultEvaluationDetails"] = result.nok_reasons
    values = [
        value
        for value in (
            _figure("Torque", result.final_torque_nm, QUANTITY_TORQUE, NEWTON_METRE),
            _figure("Angle", result.final_angle_deg, QUANTITY_ANGLE, DEGREE),
            _figure("Preload", result.final_force_n, QUANTITY_FORCE, NEWTON),
        )
        if value is not None
    ]
    if result.events is not None:
        values.append(
            {
                "Name": "StickSlipEvents",
                "MeasuredValue": float(result.events),
                "PhysicalQuantity": QUANTITY_NUMBER,
            }
        )
    if result.process_intensity is not None:
        values.append(
            {
                "Name": "ProcessIntensity",
                "MeasuredValue": result.process_intensity,
                "PhysicalQuantity": QUANTITY_OTHER,
            }
        )
    joining: dict[str, Any] = {"OverallResultValues": values}
    if result.steps:
        joining["StepResults"] = [
            _step(meta["ResultId"], number, step) for number, step in enumerate(result.steps, 1)
        ]
    if trace is not None:
        joining["Trace"] = trace
    return {"ResultMetaData": meta, "ResultContent": [joining]}


def _step(identifier: str, number: int, step: ResultStep) -> dict[str, Any]:
    """A controller's step as a StepResultDataType's fields."""
    fields: dict[str, Any] = {
        "StepResultId": f"{identifier}/step/{number}",
        "ProgramStep": str(number),
        "Name": step.name,
        "ResultEvaluation": _EVALUATION_OF_STEP[step.status],
    }
    if step.actual is not None:
        value: dict[str, Any] = {"Name": step.function or step.name, "MeasuredValue": step.actual}
        if step.nominal is not None:
            value["TargetValue"] = step.nominal
        fields["StepResultValues"] = [value]
    return fields


def _figure(
    name: str, figure: JudgedFigure, quantity: int, unit: EngineeringUnit
) -> dict[str, Any] | None:
    """One final figure as a ResultValueDataType's fields; None when it was not measured."""
    if figure.value is None:
        return None
    value: dict[str, Any] = {
        "Name": name,
        "MeasuredValue": figure.value,
        "ResultEvaluation": _EVALUATION_OF_STATUS[figure.status],
        "PhysicalQuantity": quantity,
        "EngineeringUnits": unit,
    }
    if figure.min is not None:
        value["LowLimit"] = figure.min
    if figure.max is not None:
        value["HighLimit"] = figure.max
    return value
