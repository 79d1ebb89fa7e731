"""The fields of the server's events, pure (asyncua's ``ua`` types, no server).

- :func:`base_fields`: BaseEventType's (OPC 10000-5, 6.4.2): ``EventId`` (16 random
  bytes, unique per notification), ``EventType``, ``SourceNode``, ``SourceName``,
  ``Time`` (when it happened), ``ReceiveTime`` (when the server heard of it),
  ``LocalTime`` (the server's UTC offset then), ``Message``, ``Severity`` (1 to 1000),
  and ``ConditionClassId``/``ConditionClassName`` when given;
- :func:`result_ready_fields`: ``Result`` (Machinery/Result's namespace) of a
  ``JoiningSystemResultReadyEventType``, a ``ResultDataType``;
- :func:`joining_content_fields`: IJT's ``JoiningSystemEventContent`` with ``EventCode``,
  ``EventText`` and ``JoiningTechnology`` (a variable of no value of its own);
- :func:`condition_fields`: an ``AcknowledgeableConditionType``'s state (OPC 10000-9,
  5.5.2 and 5.7.2): ``ConditionName``, ``BranchId`` (null: the trunk), ``Retain``,
  ``EnabledState`` (always enabled), ``Quality`` (Good), ``LastSeverity``, ``Comment``,
  ``ClientUserId``, ``AckedState`` and ``ConfirmedState`` with their ``Id`` and
  ``TransitionTime``; each state variable's text in English as the specification names
  the states.
"""

from __future__ import annotations

import os
import time
from datetime import UTC, datetime
from typing import Any

from asyncua import ua

from services.opcua.condition_states import ConditionState
from services.opcua.served_events import FieldPath, field_path

Fields = dict[FieldPath, ua.Variant]


def new_event_id() -> bytes:
    """A notification's EventId: 16 random bytes."""
    return os.urandom(16)


def base_fields(
    *,
    event_id: bytes,
    types: tuple[ua.NodeId, ...],
    source: tuple[ua.NodeId, str],
    time: datetime,
    message: str,
    severity: int,
    condition_class: tuple[ua.NodeId, str] | None = None,
) -> Fields:
    """BaseEventType's fields of an event of ``types[0]`` from ``source`` (node, name)."""
    source_node, source_name = source
    fields: Fields = {
        field_path("EventId"): ua.Variant(event_id, ua.VariantType.ByteString),
        field_path("EventType"): ua.Variant(types[0], ua.VariantType.NodeId),
        field_path("SourceNode"): ua.Variant(source_node, ua.VariantType.NodeId),
        field_path("SourceName"): ua.Variant(source_name, ua.VariantType.String),
        field_path("Time"): ua.Variant(time, ua.VariantType.DateTime),
        field_path("ReceiveTime"): ua.Variant(datetime.now(UTC), ua.VariantType.DateTime),
        field_path("LocalTime"): ua.Variant(_local_time(time), ua.VariantType.ExtensionObject),
        field_path("Message"): ua.Variant(ua.LocalizedText(message), ua.VariantType.LocalizedText),
        field_path("Severity"): ua.Variant(severity, ua.VariantType.UInt16),
    }
    if condition_class is not None:
        class_id, class_name = condition_class
        fields[field_path("ConditionClassId")] = ua.Variant(class_id, ua.VariantType.NodeId)
        fields[field_path("ConditionClassName")] = ua.Variant(
            ua.LocalizedText(class_name), ua.VariantType.LocalizedText
        )
    return fields


def _local_time(when: datetime) -> ua.TimeZoneDataType:
    local = time.localtime(when.timestamp())
    return ua.TimeZoneDataType(
        Offset=ua.Int16(local.tm_gmtoff // 60), DaylightSavingInOffset=bool(local.tm_isdst > 0)
    )


def result_ready_fields(result_ns: int, result: Any) -> Fields:
    """The ``Result`` of a result-ready event (a ``ua.ResultDataType``)."""
    return {field_path((result_ns, "Result")): ua.Variant(result, ua.VariantType.ExtensionObject)}


def joining_content_fields(ijt_ns: int, code: int, text: str, technology: str) -> Fields:
    """``JoiningSystemEventContent`` and its ``EventCode``, ``EventText``,
    ``JoiningTechnology`` (IJT Base's namespace)."""
    content = (ijt_ns, "JoiningSystemEventContent")
    return {
        field_path(content): ua.Variant(),
        field_path(content, (ijt_ns, "EventCode")): ua.Variant(code, ua.VariantType.Int64),
        field_path(content, (ijt_ns, "EventText")): ua.Variant(
            ua.LocalizedText(text), ua.VariantType.LocalizedText
        ),
        field_path(content, (ijt_ns, "JoiningTechnology")): ua.Variant(
            ua.LocalizedText(technology), ua.VariantType.LocalizedText
        ),
    }


def condition_fields(
    state: ConditionState, now: datetime, transitions: dict[str, datetime]
) -> Fields:
    """The state fields of ``state``'s event; ``transitions``: when ``AckedState`` and
    ``ConfirmedState`` last changed (by name)."""
    good = ua.StatusCode(ua.UInt32(ua.StatusCodes.Good))
    fields: Fields = {
        field_path("ConditionName"): ua.Variant(state.name, ua.VariantType.String),
        field_path("BranchId"): ua.Variant(ua.NodeId(), ua.VariantType.NodeId),
        field_path("Retain"): ua.Variant(state.retain, ua.VariantType.Boolean),
        field_path("Quality"): ua.Variant(good, ua.VariantType.StatusCode),
        field_path("Quality", "SourceTimestamp"): ua.Variant(now, ua.VariantType.DateTime),
        field_path("LastSeverity"): ua.Variant(state.last_severity, ua.VariantType.UInt16),
        field_path("LastSeverity", "SourceTimestamp"): ua.Variant(now, ua.VariantType.DateTime),
        field_path("Comment"): ua.Variant(
            ua.LocalizedText(state.comment), ua.VariantType.LocalizedText
        ),
        field_path("Comment", "SourceTimestamp"): ua.Variant(now, ua.VariantType.DateTime),
        field_path("ClientUserId"): ua.Variant(state.client_user, ua.VariantType.String),
    }
    for name, value, texts in (
        ("EnabledState", True, ("Disabled", "Enabled")),
        ("AckedState", state.acked, ("Unacknowledged", "Acknowledged")),
        ("ConfirmedState", state.confirmed, ("Unconfirmed", "Confirmed")),
    ):
        fields[field_path(name)] = ua.Variant(
            ua.LocalizedText(texts[value]), ua.VariantType.LocalizedText
        )
        fields[field_path(name, "Id")] = ua.Variant(value, ua.VariantType.Boolean)
        if name in transitions:
            fields[field_path(name, "TransitionTime")] = ua.Variant(
                transitions[name], ua.VariantType.DateTime
            )
    return fields
