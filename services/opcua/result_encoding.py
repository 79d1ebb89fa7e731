"""The field values of :mod:`.result_values` as asyncua's classes of the IJT model.

The classes (``ua.ResultDataType``, ``ua.JoiningResultMetaDataType``,
``ua.JoiningResultDataType``, ``ua.ResultValueDataType``...) exist once the models
are loaded (:func:`~.nodeset_loading.load_models`); before that, this module
cannot be used. A result's ``JoiningResultDataType`` carries its ``StepResults``
(``StepResultDataType``) and, when asked by id, its ``Trace``
(``JoiningTraceDataType`` of ``StepTraceDataType`` and ``TraceContentDataType``).
"""

from __future__ import annotations

from typing import Any

from asyncua import ua

from services.opcua.result_values import UNECE_NAMESPACE, EngineeringUnit


def model_class(name: str) -> Any:
    """A class the models' load generated (``ua.<name>``; mypy cannot see them)."""
    return getattr(ua, name)


#: fields that are LocalizedText in the model (plain text in :mod:`.result_values`)
LOCALIZED = frozenset({"JoiningTechnology", "Description", "ResultEvaluationDetails"})


def result_data(values: dict[str, Any]) -> Any:
    """A ``ua.ResultDataType`` (Machinery/Result) of ``values``: its ResultMetaData a
    ``JoiningResultMetaDataType``, its ResultContent one ``JoiningResultDataType`` (a
    tightening's) or a ``ResultDataType`` per sub-result it refers to (a cycle's:
    :mod:`.cycle_values`)."""
    meta = dict(values["ResultMetaData"])
    for name in LOCALIZED & meta.keys():
        meta[name] = ua.LocalizedText(meta[name])
    if "ExtendedMetaData" in meta:  # IJT's KeyValueDataType: a TrimmedString key
        meta["ExtendedMetaData"] = [
            model_class("KeyValueDataType")(Key=key, Value=ua.Variant(text, ua.VariantType.String))
            for key, text in meta["ExtendedMetaData"].items()
        ]
    for name in ("SequenceNumber",):
        if name in meta:
            meta[name] = ua.UInt64(meta[name])
    for name in ("Classification",):
        if name in meta:
            meta[name] = ua.Byte(meta[name])
    if "ResultCounters" in meta:
        meta["ResultCounters"] = [_counter(counter) for counter in meta["ResultCounters"]]
    content = [
        ua.Variant(
            result_data(item) if "ResultMetaData" in item else _joining_result(item),
            ua.VariantType.ExtensionObject,
        )
        for item in values["ResultContent"]
    ]
    return model_class("ResultDataType")(
        ResultMetaData=model_class("JoiningResultMetaDataType")(**meta), ResultContent=content
    )


def _counter(fields: dict[str, Any]) -> Any:
    """A ``ResultCounterDataType`` (IJT Base, 10.11)."""
    return model_class("ResultCounterDataType")(
        Name=fields["Name"],
        CounterValue=ua.UInt32(fields["CounterValue"]),
        CounterType=ua.Int16(fields["CounterType"]),
    )


def _joining_result(joining: dict[str, Any]) -> Any:
    fields: dict[str, Any] = {
        "OverallResultValues": [_value(item) for item in joining["OverallResultValues"]]
    }
    if "StepResults" in joining:
        fields["StepResults"] = [_step_result(step) for step in joining["StepResults"]]
    if "Trace" in joining:
        fields["Trace"] = _trace(joining["Trace"])
    return model_class("JoiningResultDataType")(**fields)


def _step_result(fields: dict[str, Any]) -> Any:
    fields = dict(fields)
    fields["ResultEvaluation"] = model_class("ResultEvaluationEnum")(fields["ResultEvaluation"])
    if "StepResultValues" in fields:
        fields["StepResultValues"] = [_value(item) for item in fields["StepResultValues"]]
    return model_class("StepResultDataType")(**fields)


def _trace(fields: dict[str, Any]) -> Any:
    """A ``JoiningTraceDataType`` of :func:`.result_trace.trace_values`'s fields."""
    steps = []
    for given in fields["StepTraces"]:
        step = dict(given)
        step["NumberOfTracePoints"] = ua.UInt32(step["NumberOfTracePoints"])
        step["StepTraceContent"] = [_trace_content(item) for item in step["StepTraceContent"]]
        steps.append(model_class("StepTraceDataType")(**step))
    return model_class("JoiningTraceDataType")(
        TraceId=fields["TraceId"], ResultId=fields["ResultId"], StepTraces=steps
    )


def _trace_content(fields: dict[str, Any]) -> Any:
    fields = dict(fields)
    fields["PhysicalQuantity"] = ua.Byte(fields["PhysicalQuantity"])
    fields["EngineeringUnits"] = eu_information(fields["EngineeringUnits"])
    return model_class("TraceContentDataType")(**fields)


def _value(fields: dict[str, Any]) -> Any:
    fields = dict(fields)
    unit = fields.pop("EngineeringUnits", None)
    if "ResultEvaluation" in fields:
        fields["ResultEvaluation"] = model_class("ResultEvaluationEnum")(fields["ResultEvaluation"])
    if "PhysicalQuantity" in fields:
        fields["PhysicalQuantity"] = ua.Byte(fields["PhysicalQuantity"])
    if unit is not None:
        fields["EngineeringUnits"] = eu_information(unit)
    return model_class("ResultValueDataType")(**fields)


def eu_information(unit: EngineeringUnit) -> ua.EUInformation:
    """OPC 10000-8's EUInformation of a UNECE unit."""
    return ua.EUInformation(
        NamespaceUri=UNECE_NAMESPACE,
        UnitId=unit.unit_id,
        DisplayName=ua.LocalizedText(unit.display_name),
        Description=ua.LocalizedText(unit.description),
    )
