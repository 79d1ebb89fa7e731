"""GetResultIdListFiltered's ``Filter`` and ``OrderedBy`` as a :class:`ResultsQuery` of a station.

Machinery/Result's method (OPC 40001-101, 7.1.3) takes a ``ContentFilter``
(OPC 10000-4, 7.7) over the result's metadata: each operand a
``SimpleAttributeOperand`` whose ``BrowsePath`` is built from the fields of
``ResultType`` (``ResultMetaData/CreationTime``) or of the result-ready event
(``Result/ResultMetaData/CreationTime``). :func:`filtered_query` (pure: asyncua's
classes, no server) maps what the results store can answer onto
:class:`~shared.results.ResultsQuery` and refuses the rest with the status code of
OPC 10000-4 that says why (:class:`UnsupportedFilterError`, the argument and its code):

======================  ==================================  =========================
field of ResultMetaData  comparisons                         ResultsQuery
======================  ==================================  =========================
``CreationTime``         Equals, GreaterThan(OrEqual),       ``since_ns``/``until_ns``
                         LessThan(OrEqual), Between
``ResultEvaluation``     Equals 1 (OK), 2 (NotOK)            ``verdict``
``PartId``               Equals                              ``part_id``
``InternalRecipeId``     Equals (the program id as text)     ``program_id``
``ResultId``             Equals (``<station>/<run id>``)     ``run_id``
======================  ==================================  =========================

- The element 0 is the filter's root; ``And`` joins comparisons (and other
  ``And``\\ s, each by an ``ElementOperand`` to a later element). An empty or null
  filter asks for every result of the station.
- A comparison holds a field and a ``LiteralOperand``, in either order. A
  value no result can have (ResultEvaluation 3, a ResultId or program id not as
  the server writes one (:func:`~.result_values.parse_result_id`), another
  station's ResultId, two different PartIds) matches nothing: no query.
- ``CreationTime`` is the end of the run to the microsecond (what the server
  sends: :func:`~.result_values.utc_time`), compared with a literal's whole
  microseconds, so a bound is exact against the store's nanoseconds; a bound
  beyond an int64's nanoseconds (before 1677, after 2262) is no bound, or
  matches nothing (``> 9999-12-31``).
- Names in a path are compared in the Machinery/Result namespace or without one
  (a structure's field names have none); the ``TypeDefinitionId`` is not looked at;
  ``AttributeId`` is Value, ``IndexRange`` empty.
- Refused (``Bad_InvalidArgument`` for the call, the code below for the argument):
  ``Or``, ``Not``, ``Like``, ``InList`` and the other operators
  (``Bad_FilterOperatorUnsupported``); a field not in the table, e.g.
  ``SequenceNumber``, or a comparison it does not have (``Bad_NotSupported``);
  an operand of another kind, a literal of the wrong type, a wrong count of
  operands (``Bad_FilterOperandInvalid``, ``Bad_FilterOperandCountMismatch``); an
  ``ElementOperand`` to no later element, or to one another operand refers to
  (``Bad_FilterElementInvalid``: each element is read once); more than
  :data:`MAX_FILTER_ELEMENTS` elements (``Bad_ContentFilterInvalid``).
- ``OrderedBy`` empty or null: newest first (the spec leaves the order to the
  server); ``[CreationTime]``: oldest first (a criterion has no direction: it
  ascends); anything else ``Bad_NotSupported``.
"""

from __future__ import annotations

from dataclasses import replace
from datetime import UTC, datetime, timedelta
from typing import Any

from asyncua import ua

from services.opcua.result_values import (
    EPOCH,
    EVALUATION_NOT_OK,
    EVALUATION_OK,
    parse_id,
    parse_result_id,
)
from shared.contract import INT64_MAX
from shared.results import ResultsQuery

#: the input arguments of GetResultIdListFiltered, by their index
FILTER_ARGUMENT = 0
ORDERED_BY_ARGUMENT = 1
#: the elements of a filter at most (five fields, a few comparisons each, and their Ands)
MAX_FILTER_ELEMENTS = 64
#: the path of a field of the result's metadata: ResultType's, or the event's Result
METADATA_PATHS = (("ResultMetaData",), ("Result", "ResultMetaData"))
#: the fields of ResultMetaData the results store filters on
FIELDS = ("CreationTime", "ResultEvaluation", "PartId", "InternalRecipeId", "ResultId")
_MICROSECOND = timedelta(microseconds=1)
_INT64_MIN = -INT64_MAX - 1
_VERDICT_OF_EVALUATION = {EVALUATION_OK: "OK", EVALUATION_NOT_OK: "NOK"}
_Op = ua.FilterOperator
_MIRRORED = {  # literal first: the comparison seen from the field
    _Op.Equals: _Op.Equals,
    _Op.GreaterThan: _Op.LessThan,
    _Op.LessThan: _Op.GreaterThan,
    _Op.GreaterThanOrEqual: _Op.LessThanOrEqual,
    _Op.LessThanOrEqual: _Op.GreaterThanOrEqual,
}


class UnsupportedFilterError(ValueError):
    """An input argument the results store cannot answer: which, its status code, why."""

    def __init__(self, argument: int, status: int, reason: str) -> None:
        super().__init__(reason)
        self.argument = argument
        self.status = status


class _NoMatchError(Exception):
    """A criterion no result can meet."""


def filtered_query(
    station: str, content_filter: Any, ordered_by: Any, result_ns: int
) -> ResultsQuery | None:
    """The query of ``station``'s results the filter asks for (no limit); None when no result
    can match; :class:`UnsupportedFilterError` for what does not map."""
    query = ResultsQuery(
        stations=[station], limit=None, oldest_first=_oldest_first(ordered_by, result_ns)
    )
    elements = [] if content_filter is None else list(content_filter.Elements or [])
    if not elements:
        return query
    try:
        return _walked(elements, query, station, result_ns)
    except _NoMatchError:
        return None


def _walked(elements: list[Any], query: ResultsQuery, station: str, result_ns: int) -> ResultsQuery:
    """``query`` with the criteria of the element 0 and every element its ``And``\\ s join,
    walked with a list of the elements still to read (no recursion); an element that two
    operands refer to is refused (walking it once per reference was exponential)."""
    if len(elements) > MAX_FILTER_ELEMENTS:
        raise _refused(
            ua.StatusCodes.BadContentFilterInvalid,
            f"{len(elements)} elements: at most {MAX_FILTER_ELEMENTS}",
        )
    referred = {0}
    waiting = [0]
    while waiting:
        index = waiting.pop()
        element = elements[index]
        operator, operands = element.FilterOperator, list(element.FilterOperands or [])
        if operator != _Op.And:
            query = _criterion(operator, operands, query, station, result_ns)
            continue
        _count(operands, 2)
        for operand in operands:
            if not isinstance(operand, ua.ElementOperand):
                raise _refused(ua.StatusCodes.BadFilterOperandInvalid, "And joins elements")
            if not index < operand.Index < len(elements) or operand.Index in referred:
                raise _refused(
                    ua.StatusCodes.BadFilterElementInvalid,
                    f"element {index} refers to element {operand.Index}: not a later one, or "
                    "one another operand refers to",
                )
            referred.add(operand.Index)
        waiting.extend(operand.Index for operand in reversed(operands))  # the first first
    return query


def _criterion(
    operator: Any, operands: list[Any], query: ResultsQuery, station: str, result_ns: int
) -> ResultsQuery:
    """``query`` with the criterion of a comparison or a Between."""
    if operator == _Op.Between:
        _count(operands, 3)
        field, low, high = operands
        name = _field(field, result_ns)
        if name != "CreationTime":
            raise _refused(ua.StatusCodes.BadNotSupported, f"{name} has no Between here")
        query = _time(query, _Op.GreaterThanOrEqual, _literal(low, datetime))
        return _time(query, _Op.LessThanOrEqual, _literal(high, datetime))
    if operator in _MIRRORED:
        _count(operands, 2)
        first, second = operands
        if isinstance(first, ua.LiteralOperand):
            first, second, operator = second, first, _MIRRORED[operator]
        return _compare(query, _field(first, result_ns), operator, second, station)
    name = _Op(operator).name if operator in iter(_Op) else str(operator)
    raise _refused(
        ua.StatusCodes.BadFilterOperatorUnsupported,
        f"operator {name}: only And, Equals, comparisons and Between",
    )


def _compare(
    query: ResultsQuery, name: str, operator: Any, literal: Any, station: str
) -> ResultsQuery:
    if name == "CreationTime":
        return _time(query, operator, _literal(literal, datetime))
    if operator != _Op.Equals:
        raise _refused(ua.StatusCodes.BadNotSupported, f"{name} is compared by Equals only")
    if name == "ResultEvaluation":
        verdict = _VERDICT_OF_EVALUATION.get(_literal(literal, int))
        return _same(query, "verdict", verdict)
    text = _literal(literal, str)
    if name == "PartId":
        return _same(query, "part_id", text)
    if name == "InternalRecipeId":
        return _same(query, "program_id", parse_id(text))
    parsed = parse_result_id(text)
    return _same(query, "run_id", parsed[1] if parsed and parsed[0] == station else None)


def _same(query: ResultsQuery, criterion: str, value: Any) -> ResultsQuery:
    """``query`` with ``criterion`` equal to ``value`` (None: no result has it)."""
    if value is None or getattr(query, criterion) not in (None, value):
        raise _NoMatchError
    return replace(query, **{criterion: value})


def _time(query: ResultsQuery, operator: Any, when: datetime) -> ResultsQuery:
    """``query`` within a bound on CreationTime: a result's is its end's whole microseconds,
    ``ended_ns // 1000``; against a literal's ``t`` µs, ``>= t`` is ``ended_ns >= t * 1000``
    and ``> t`` is ``>= (t + 1) * 1000`` (``<`` and ``<=`` likewise, on ``until_ns``).

    A bound beyond the nanoseconds an int64 holds (before 1677-09-21, after 2262-04-11; the
    store's ``ended_ns`` is one) is no bound on the side every end is within, and matches
    nothing on the other (e.g. ``< 9999-12-31`` every result, ``> 9999-12-31`` none)."""
    if when.tzinfo is None:
        when = when.replace(tzinfo=UTC)
    micros = (when - EPOCH) // _MICROSECOND
    since = {_Op.GreaterThanOrEqual: micros, _Op.GreaterThan: micros + 1, _Op.Equals: micros}
    until = {_Op.LessThan: micros, _Op.LessThanOrEqual: micros + 1, _Op.Equals: micros + 1}
    if operator in since and (bound := since[operator] * 1000) > _INT64_MIN:
        if bound > INT64_MAX:
            raise _NoMatchError
        query = replace(
            query, since_ns=bound if query.since_ns is None else max(bound, query.since_ns)
        )
    if operator in until and (bound := until[operator] * 1000) <= INT64_MAX:
        if bound <= _INT64_MIN:
            raise _NoMatchError
        query = replace(
            query, until_ns=bound if query.until_ns is None else min(bound, query.until_ns)
        )
    since_ns, until_ns = query.since_ns, query.until_ns
    if since_ns is not None and until_ns is not None and since_ns >= until_ns:
        raise _NoMatchError
    return query


def _field(operand: Any, result_ns: int) -> str:
    """The name of the metadata field ``operand`` reads."""
    if not isinstance(operand, ua.SimpleAttributeOperand):
        raise _refused(
            ua.StatusCodes.BadFilterOperandInvalid,
            f"a comparison holds a SimpleAttributeOperand and a LiteralOperand, not "
            f"{type(operand).__name__}",
        )
    name = _metadata_field(list(operand.BrowsePath or []), result_ns)
    if name not in FIELDS:
        shown = "/".join(qualified.to_string() for qualified in operand.BrowsePath or [])
        raise _refused(
            ua.StatusCodes.BadNotSupported,
            f"{shown}: the results store filters on ResultMetaData's {', '.join(FIELDS)}",
        )
    if operand.AttributeId != ua.AttributeIds.Value or operand.IndexRange:
        raise _refused(ua.StatusCodes.BadFilterOperandInvalid, "a field's Value, whole")
    return name


def _metadata_field(path: list[Any], result_ns: int) -> str | None:
    """The field of ResultMetaData a path of QualifiedNames names, if it names one."""
    names = tuple(name.Name for name in path if name.NamespaceIndex in (0, result_ns))
    if len(names) != len(path) or names[:-1] not in METADATA_PATHS:
        return None
    return names[-1]


def _literal(operand: Any, kind: type) -> Any:
    value = operand.Value.Value if isinstance(operand, ua.LiteralOperand) else None
    if not isinstance(value, kind) or isinstance(value, bool):
        raise _refused(
            ua.StatusCodes.BadFilterOperandInvalid,
            f"a LiteralOperand of a {kind.__name__} expected, not {operand!r}",
        )
    return value


def _count(operands: list[Any], count: int) -> None:
    if len(operands) != count:
        raise _refused(
            ua.StatusCodes.BadFilterOperandCountMismatch,
            f"{count} operands expected, not {len(operands)}",
        )


def _oldest_first(ordered_by: Any, result_ns: int) -> bool:
    """OrderedBy: none, newest first; ``[CreationTime]``, oldest first."""
    if not ordered_by:
        return False
    names = [
        _metadata_field([element.TargetName for element in path.Elements or []], result_ns)
        for path in ordered_by
    ]
    if names == ["CreationTime"]:
        return True
    raise UnsupportedFilterError(
        ORDERED_BY_ARGUMENT,
        ua.StatusCodes.BadNotSupported,
        "OrderedBy: the results store orders by ResultMetaData/CreationTime only",
    )


def _refused(status: int, reason: str) -> UnsupportedFilterError:
    return UnsupportedFilterError(FILTER_ARGUMENT, status, reason)
