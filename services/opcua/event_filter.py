"""A client's EventFilter applied to one :class:`~.served_events.ServedEvent`, pure (asyncua's
``ua`` types, no server).

:func:`where_matches` evaluates the filter's where clause (OPC 10000-4, 7.7): element 0
is the root; an ``ElementOperand`` refers to another element; a ``SimpleAttributeOperand``
is a field of the event (:meth:`~.served_events.ServedEvent.value`); a ``LiteralOperand``
its value. The operators: ``Equals``, ``IsNull``, ``GreaterThan``, ``LessThan``,
``GreaterThanOrEqual``, ``LessThanOrEqual``, ``Like`` (``%``, ``_``, ``[...]``, ``[^...]``,
``\\`` escaping), ``Not``, ``Between``, ``InList``, ``And``, ``Or``, ``BitwiseAnd``,
``BitwiseOr`` and ``OfType`` (the event is of the type *or of a subtype*). A comparison
with a null operand, or of values that do not compare, is unknown, and ``Not``, ``And``
and ``Or`` carry unknown as OPC UA's three-valued logic says; the event is delivered
when the root is true. An empty where clause matches every event. ``Cast``, ``InView``,
``RelatedTo`` and an ``AttributeOperand`` raise :class:`UnsupportedFilterError` (the
server cannot answer them: the event is not delivered to that monitored item).

:func:`selected` gives the select clauses' values in their order: a field by its browse
path (into a structure's fields past a field), null where the event has none; the
``NodeId`` attribute with an empty path is a condition's ``ConditionId``. A clause whose
``TypeDefinitionId`` is an event type the event is not of (nor of a subtype of) selects
null (BaseEventType or none: any event's field of that path).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any

from asyncua import ua

from services.opcua.nodeset_loading import node_id
from services.opcua.served_events import ServedEvent

Op = ua.FilterOperator
BASE_EVENT_TYPE = node_id(ua.ObjectIds.BaseEventType)
#: where clauses longer than this are refused (as GetResultIdListFiltered's)
MAX_ELEMENTS = 64


class UnsupportedFilterError(ValueError):
    """A where clause the server cannot evaluate (its operator or operand, named)."""


def where_matches(where: ua.ContentFilter | None, event: ServedEvent) -> bool:
    """The event passes the where clause (True only when its root is true, not unknown)."""
    elements = list(where.Elements or []) if where is not None else []
    if not elements:
        return True
    if len(elements) > MAX_ELEMENTS:
        raise UnsupportedFilterError(f"{len(elements)} elements (at most {MAX_ELEMENTS})")
    return _Evaluation(elements, event).element(0, ()) is True


def selected(
    select_clauses: Sequence[ua.SimpleAttributeOperand], event: ServedEvent
) -> list[ua.Variant]:
    """The values the select clauses ask, in their order (a null variant for none)."""
    return [_select(clause, event) or ua.Variant() for clause in select_clauses]


def _select(clause: ua.SimpleAttributeOperand, event: ServedEvent) -> ua.Variant | None:
    type_id = clause.TypeDefinitionId
    if (
        type_id is not None
        and not type_id.is_null()
        and type_id != BASE_EVENT_TYPE
        and not event.is_of_type(type_id)
    ):
        return None
    path = list(clause.BrowsePath or [])
    if clause.AttributeId == ua.AttributeIds.NodeId and not path:
        if event.condition_id is None:
            return None
        return ua.Variant(event.condition_id, ua.VariantType.NodeId)
    if clause.AttributeId != ua.AttributeIds.Value or not path:
        return None
    return event.value(path)


class _Evaluation:
    """One where clause over one event; each element evaluated at most once per path of
    references (a loop of ElementOperands is refused)."""

    def __init__(self, elements: list[ua.ContentFilterElement], event: ServedEvent) -> None:
        self._elements = elements
        self._event = event

    def element(self, index: int, within: tuple[int, ...]) -> Any:
        if not 0 <= index < len(self._elements) or index in within:
            raise UnsupportedFilterError(f"element {index}: no such element, or a loop")
        item = self._elements[index]
        operator = item.FilterOperator
        operands = list(item.FilterOperands or [])
        here = (*within, index)

        def value(position: int) -> Any:
            if position >= len(operands):
                raise UnsupportedFilterError(
                    f"element {index}: {operator.name} needs more operands"
                )
            return self._operand(operands[position], here)

        return _apply(operator, value, len(operands), self._event, index)

    def _operand(self, operand: Any, within: tuple[int, ...]) -> Any:
        if isinstance(operand, ua.ExtensionObject):  # not decoded: not an operand we know
            raise UnsupportedFilterError("an operand the server cannot decode")
        if isinstance(operand, ua.ElementOperand):
            return self.element(int(operand.Index), within)
        if isinstance(operand, ua.LiteralOperand):
            return operand.Value.Value if operand.Value is not None else None
        if isinstance(operand, ua.SimpleAttributeOperand):
            found = _select(operand, self._event)
            return None if found is None else found.Value
        raise UnsupportedFilterError(f"a {type(operand).__name__}")


def _apply(operator: Op, value: Any, count: int, event: ServedEvent, index: int) -> Any:
    """``operator`` on its operands (``value(i)``, evaluated when needed)."""
    if operator == Op.And:
        return _and(value(0), value(1))
    if operator == Op.Or:
        return _or(value(0), value(1))
    if operator == Op.Not:
        inner = value(0)
        return None if inner is None else not _truth(inner)
    if operator == Op.IsNull:
        return value(0) is None
    if operator == Op.OfType:
        type_id = value(0)
        return isinstance(type_id, ua.NodeId) and event.is_of_type(type_id)
    if operator == Op.InList:
        first = value(0)
        found = [_compare(Op.Equals, first, value(i)) for i in range(1, count)]
        return True if True in found else (None if None in found else False)
    if operator == Op.Between:
        low, high = _compare(Op.GreaterThanOrEqual, value(0), value(1)), None
        if low is not False:
            high = _compare(Op.LessThanOrEqual, value(0), value(2))
        return _and(low, high)
    if operator == Op.Like:
        return _like(value(0), value(1))
    if operator in (Op.BitwiseAnd, Op.BitwiseOr):
        left, right = value(0), value(1)
        if not (_is_integer(left) and _is_integer(right)):
            return None
        return left & right if operator == Op.BitwiseAnd else left | right
    if operator in _COMPARISONS:
        return _compare(operator, value(0), value(1))
    raise UnsupportedFilterError(f"element {index}: the {operator.name} operator")


_COMPARISONS = {
    Op.Equals: lambda a, b: a == b,
    Op.GreaterThan: lambda a, b: a > b,
    Op.LessThan: lambda a, b: a < b,
    Op.GreaterThanOrEqual: lambda a, b: a >= b,
    Op.LessThanOrEqual: lambda a, b: a <= b,
}


def _compare(operator: Op, left: Any, right: Any) -> bool | None:
    """Unknown (None) with a null operand or values of kinds that do not compare."""
    if left is None or right is None:
        return None
    left, right = _comparable(left), _comparable(right)
    if _is_number(left) != _is_number(right) or (
        not _is_number(left) and type(left) is not type(right)
    ):
        return False if operator == Op.Equals else None
    try:
        return bool(_COMPARISONS[operator](left, right))
    except TypeError:
        return None


def _comparable(value: Any) -> Any:
    """A LocalizedText by its text, an enumeration by its number, bytes as they are."""
    if isinstance(value, ua.LocalizedText):
        return value.Text
    if isinstance(value, bool):
        return value
    if isinstance(value, int):  # IntEnum too
        return int(value)
    return value


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _is_integer(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _truth(value: Any) -> bool:
    return bool(value)


def _and(left: Any, right: Any) -> bool | None:
    if left is False or right is False:
        return False
    if left is None or right is None:
        return None
    return _truth(left) and _truth(right)


def _or(left: Any, right: Any) -> bool | None:
    if left is True or right is True:
        return True
    if left is None or right is None:
        return None
    return _truth(left) or _truth(right)


def _like(text: Any, pattern: Any) -> bool | None:
    text, pattern = _comparable(text), _comparable(pattern)
    if not isinstance(text, str) or not isinstance(pattern, str):
        return None
    return re.fullmatch(like_pattern(pattern), text, flags=re.DOTALL) is not None


def like_pattern(pattern: str) -> str:
    """OPC UA's Like pattern (OPC 10000-4, 7.7.3) as a regular expression."""
    out: list[str] = []
    position = 0
    while position < len(pattern):
        char = pattern[position]
        if char == "\\" and position + 1 < len(pattern):
            out.append(re.escape(pattern[position + 1]))
            position += 2
            continue
        if char == "%":
            out.append(".*")
        elif char == "_":
            out.append(".")
        elif char == "[" and "]" in pattern[position + 1 :]:
            end = pattern.index("]", position + 1)
            inside = pattern[position + 1 : end]
            negate = inside.startswith("^")
            body = "".join(re.escape(c) if c != "-" else "-" for c in inside[negate:])
            out.append(f"[{'^' if negate else ''}{body}]")
            position = end + 1
            continue
        else:
            out.append(re.escape(char))
        position += 1
    return "".join(out)
