"""A client's EventFilter on one served event: fields by browse path (into a structure's
fields), the where clause's operators with OfType answering subtypes, and OPC UA's
three-valued logic. Pure: asyncua's ``ua`` types, no server."""

from __future__ import annotations

from typing import Any

import pytest
from asyncua import ua

from services.opcua.event_filter import (
    UnsupportedFilterError,
    like_pattern,
    selected,
    where_matches,
)
from services.opcua.nodeset_loading import node_id
from services.opcua.served_events import ServedEvent, field_path

Op = ua.FilterOperator
IJT = 5
#: a type, its supertype and BaseEventType (as a condition's: ConditionType below it)
OWN_TYPE = node_id(1020, IJT)
ACKNOWLEDGEABLE = node_id(ua.ObjectIds.AcknowledgeableConditionType)
CONDITION = node_id(ua.ObjectIds.ConditionType)
BASE = node_id(ua.ObjectIds.BaseEventType)
UNIT = ua.EUInformation(
    NamespaceUri="http://www.opcfoundation.org/UA/units/un/cefact",
    UnitId=4403766,
    DisplayName=ua.LocalizedText("N·m"),
)


def _event(**more: Any) -> ServedEvent:
    fields = {
        field_path("EventType"): ua.Variant(OWN_TYPE, ua.VariantType.NodeId),
        field_path("Message"): ua.Variant(
            ua.LocalizedText("tool 7 is due"), ua.VariantType.LocalizedText
        ),
        field_path("Severity"): ua.Variant(500, ua.VariantType.UInt16),
        field_path((IJT, "JoiningSystemEventContent"), (IJT, "EventCode")): ua.Variant(
            1, ua.VariantType.Int64
        ),
        field_path((IJT, "Unit")): ua.Variant(UNIT, ua.VariantType.ExtensionObject),
        field_path("AckedState", "Id"): ua.Variant(False, ua.VariantType.Boolean),
    }
    return ServedEvent(
        types=(OWN_TYPE, ACKNOWLEDGEABLE, CONDITION, BASE),
        fields=fields,
        condition_id=more.get("condition_id", node_id("st1/conditions/wear/7", 9)),
    )


def _clause(*names: tuple[int, str] | str, type_id: ua.NodeId = BASE) -> ua.SimpleAttributeOperand:
    return ua.SimpleAttributeOperand(
        TypeDefinitionId=type_id,
        BrowsePath=[
            ua.QualifiedName(name, 0)
            if isinstance(name, str)
            else ua.QualifiedName(name[1], name[0])
            for name in names
        ],
        AttributeId=ua.AttributeIds.Value,
    )


def _where(*elements: tuple[Op, list[Any]]) -> ua.ContentFilter:
    return ua.ContentFilter(
        Elements=[
            ua.ContentFilterElement(FilterOperator=op, FilterOperands=operands)
            for op, operands in elements
        ]
    )


def _literal(value: Any, kind: ua.VariantType | None = None) -> ua.LiteralOperand:
    return ua.LiteralOperand(Value=ua.Variant(value) if kind is None else ua.Variant(value, kind))


def _element(index: int) -> ua.ElementOperand:
    return ua.ElementOperand(Index=index)


def test_fields_are_selected_by_their_paths_and_into_a_structure_s_fields() -> None:
    event = _event()
    condition_id = ua.SimpleAttributeOperand(
        TypeDefinitionId=CONDITION, AttributeId=ua.AttributeIds.NodeId
    )
    values = selected(
        [
            _clause("Message"),
            _clause((IJT, "JoiningSystemEventContent"), (IJT, "EventCode")),
            _clause((IJT, "Unit"), "DisplayName"),
            _clause((IJT, "Unit"), (IJT, "UnitId")),  # a structure's field: any namespace
            _clause((IJT, "Unit"), "NoSuchField"),
            _clause("NoSuchField"),
            _clause("Message", type_id=node_id(ua.ObjectIds.AuditEventType)),  # not its type
            _clause("Message", type_id=ACKNOWLEDGEABLE),  # a supertype of its type
            condition_id,
        ],
        event,
    )
    assert values[0] == ua.Variant(ua.LocalizedText("tool 7 is due"), ua.VariantType.LocalizedText)
    assert values[1] == ua.Variant(1, ua.VariantType.Int64)
    assert values[2] == ua.Variant(ua.LocalizedText("N·m"), ua.VariantType.LocalizedText)
    assert values[3] == ua.Variant(4403766, ua.VariantType.Int32)
    assert values[4:7] == [ua.Variant(), ua.Variant(), ua.Variant()]
    assert values[7] == values[0]
    assert values[8] == ua.Variant(node_id("st1/conditions/wear/7", 9), ua.VariantType.NodeId)
    assert selected([condition_id], _event(condition_id=None)) == [ua.Variant()]


def test_of_type_answers_the_event_s_type_and_its_supertypes() -> None:
    event = _event()
    for type_id in (OWN_TYPE, ACKNOWLEDGEABLE, CONDITION, BASE):
        assert where_matches(_where((Op.OfType, [_literal(type_id)])), event), type_id
    other = node_id(ua.ObjectIds.AlarmConditionType)
    assert not where_matches(_where((Op.OfType, [_literal(other)])), event)
    either = _where(
        (Op.Or, [_element(1), _element(2)]),
        (Op.OfType, [_literal(other)]),
        (Op.OfType, [_literal(ACKNOWLEDGEABLE)]),
    )
    assert where_matches(either, event)
    assert where_matches(None, event) and where_matches(ua.ContentFilter(), event)


def test_comparisons_of_fields_and_literals() -> None:
    event = _event()
    severity = _clause("Severity")
    code = _clause((IJT, "JoiningSystemEventContent"), (IJT, "EventCode"))
    cases: list[tuple[tuple[Op, list[Any]], bool]] = [
        ((Op.Equals, [severity, _literal(500)]), True),
        ((Op.Equals, [code, _literal(1.0)]), True),  # numbers of other types compare
        ((Op.GreaterThan, [severity, _literal(499)]), True),
        ((Op.LessThanOrEqual, [severity, _literal(499)]), False),
        ((Op.Between, [severity, _literal(100), _literal(700)]), True),
        ((Op.InList, [severity, _literal(100), _literal(500)]), True),
        ((Op.Like, [_clause("Message"), _literal("tool _ is%")]), True),
        ((Op.Like, [_clause("Message"), _literal("tool [^7]%")]), False),
        ((Op.IsNull, [_clause("NoSuchField")]), True),
        ((Op.Equals, [_clause("Message"), _literal(500)]), False),  # text against a number
    ]
    for element, expected in cases:
        assert where_matches(_where(element), event) is expected, element
    masked = _where(
        (Op.Equals, [_element(1), _literal(4)]), (Op.BitwiseAnd, [severity, _literal(4)])
    )
    assert where_matches(masked, event)  # 500 & 4


def test_null_operands_are_unknown_and_not_and_or_carry_it() -> None:
    """OPC 10000-4, 7.7.3: a comparison with a null is unknown; Not(unknown) is unknown, not
    true; And(false, unknown) is false; Or(true, unknown) is true."""
    event = _event()
    unknown = (Op.GreaterThan, [_clause("NoSuchField"), _literal(1)])
    true = (Op.Equals, [_literal(1), _literal(1)])
    false = (Op.Equals, [_literal(1), _literal(2)])
    assert not where_matches(_where(unknown), event)
    assert not where_matches(_where((Op.Not, [_element(1)]), unknown), event)
    assert not where_matches(_where((Op.And, [_element(1), _element(2)]), true, unknown), event)
    assert where_matches(
        _where((Op.Not, [_element(1)]), (Op.And, [_element(2), _element(3)]), false, unknown), event
    )
    assert where_matches(_where((Op.Or, [_element(1), _element(2)]), true, unknown), event)


@pytest.mark.parametrize(
    "where",
    [
        _where((Op.Cast, [_literal(1), _literal(node_id(ua.ObjectIds.String))])),
        _where((Op.RelatedTo, [_literal(1), _literal(2), _literal(3), _literal(1)])),
        _where((Op.Not, [_element(0)])),  # a loop
        _where((Op.Not, [_element(5)])),  # no such element
        _where((Op.Equals, [_literal(1)])),  # an operand missing
        _where((Op.Equals, [ua.AttributeOperand(), _literal(1)])),
        _where(*[(Op.Equals, [_literal(1), _literal(1)])] * 65),
    ],
    ids=[
        "Cast",
        "RelatedTo",
        "loop",
        "no element",
        "missing operand",
        "AttributeOperand",
        "too long",
    ],
)
def test_what_the_server_cannot_evaluate_is_said(where: ua.ContentFilter) -> None:
    with pytest.raises(UnsupportedFilterError):
        where_matches(where, _event())


def test_like_patterns() -> None:
    assert like_pattern("a%b_c") == "a.*b.c"
    assert like_pattern("100\\%") == "100%"
    assert like_pattern("[a-c]x[^0-9]") == "[a-c]x[^0-9]"
