"""GetResultIdListFiltered's ContentFilter as a results query, pure (asyncua's classes, no
server): the shapes of filter a client can send to make the server work without end, and
texts that are no ids. The filters the store answers, over the wire, are in
``test_result_management.py``."""

from __future__ import annotations

from typing import Any

import pytest
from asyncua import ua

from services.opcua.result_filter import (
    MAX_FILTER_ELEMENTS,
    UnsupportedFilterError,
    filtered_query,
)

RESULT_NS = 3
Op = ua.FilterOperator


def _filter(*elements: tuple[Any, list[Any]]) -> ua.ContentFilter:
    return ua.ContentFilter(
        Elements=[
            ua.ContentFilterElement(FilterOperator=operator, FilterOperands=operands)
            for operator, operands in elements
        ]
    )


def _part_is(part_id: str) -> tuple[Any, list[Any]]:
    field = ua.SimpleAttributeOperand(
        BrowsePath=[ua.QualifiedName(name, RESULT_NS) for name in ("ResultMetaData", "PartId")],
        AttributeId=ua.AttributeIds.Value,
    )
    return Op.Equals, [field, ua.LiteralOperand(Value=ua.Variant(part_id))]


def _chain(ands: int) -> ua.ContentFilter:
    """``And(1, 2), PartId P, And(3, 4), PartId P, ..., PartId P, PartId P``: each element
    referred to once, ``2 * ands + 1`` elements."""
    elements = []
    for index in range(0, 2 * ands, 2):
        elements += [(Op.And, [ua.ElementOperand(index + 1), ua.ElementOperand(index + 2)])]
        elements += [_part_is("P")]
    return _filter(*elements, _part_is("P"))


def _refusal(content_filter: ua.ContentFilter) -> int:
    with pytest.raises(UnsupportedFilterError) as refused:
        filtered_query("st1", content_filter, None, RESULT_NS)
    return refused.value.status


def test_an_element_referred_to_twice_is_refused() -> None:
    """``And(i + 1, i + 1)`` 22 deep was 2^22 walks of the same elements."""
    doubled = [(Op.And, [ua.ElementOperand(i + 1), ua.ElementOperand(i + 1)]) for i in range(22)]
    assert _refusal(_filter(*doubled, _part_is("P"))) == ua.StatusCodes.BadFilterElementInvalid
    # two Ands joining the same comparison: a diamond, no cycle, still refused
    diamond = _filter(
        (Op.And, [ua.ElementOperand(1), ua.ElementOperand(2)]),
        (Op.And, [ua.ElementOperand(3), ua.ElementOperand(4)]),
        (Op.And, [ua.ElementOperand(3), ua.ElementOperand(4)]),
        _part_is("P"),
        _part_is("P"),
    )
    assert _refusal(diamond) == ua.StatusCodes.BadFilterElementInvalid


def test_a_filter_of_more_elements_than_the_server_takes_is_refused() -> None:
    """A chain of 1500 was a RecursionError; the most the server takes are answered."""
    assert _refusal(_chain(750)) == ua.StatusCodes.BadContentFilterInvalid
    most = _chain((MAX_FILTER_ELEMENTS - 1) // 2)
    assert len(most.Elements) == MAX_FILTER_ELEMENTS - 1
    query = filtered_query("st1", most, None, RESULT_NS)
    assert query is not None and query.part_id == "P"
    most.Elements.append(ua.ContentFilterElement(FilterOperator=Op.Equals))  # not referred to
    assert filtered_query("st1", most, None, RESULT_NS) == query
    most.Elements.append(ua.ContentFilterElement(FilterOperator=Op.Equals))
    assert _refusal(most) == ua.StatusCodes.BadContentFilterInvalid


@pytest.mark.parametrize("field", ["ResultId", "InternalRecipeId"])
@pytest.mark.parametrize("text", ["--5", "²", "-5", "05", "9223372036854775808", "", "+5"])
def test_an_id_the_server_never_gives_matches_nothing(field: str, text: str) -> None:
    path = [ua.QualifiedName(name, RESULT_NS) for name in ("ResultMetaData", field)]
    operand = ua.SimpleAttributeOperand(BrowsePath=path, AttributeId=ua.AttributeIds.Value)
    literal = f"st1/{text}" if field == "ResultId" else text
    equals = (Op.Equals, [operand, ua.LiteralOperand(Value=ua.Variant(literal))])
    assert filtered_query("st1", _filter(equals), None, RESULT_NS) is None
