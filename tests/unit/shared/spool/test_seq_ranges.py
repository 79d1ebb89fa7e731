"""Sequence numbers kept as ranges: what a recorder has of a station's spool."""

from __future__ import annotations

import itertools

from hypothesis import given
from hypothesis import strategies as st

from shared.spool import SeqRanges

ranges_strategy = st.lists(
    st.tuples(st.integers(1, 200), st.integers(0, 20)).map(lambda t: (t[0], t[0] + t[1])),
    max_size=20,
)


@given(ranges_strategy)
def test_ranges_hold_exactly_the_numbers_added_merged_and_sorted(
    added: list[tuple[int, int]],
) -> None:
    held = SeqRanges()
    numbers: set[int] = set()
    for first, last in added:
        held.add_range(first, last)
        numbers.update(range(first, last + 1))
    assert {n for n in range(0, 260) if n in held} == numbers
    pairs = list(held)
    assert pairs == sorted(pairs)
    for (_, end), (start, _) in itertools.pairwise(pairs):
        assert start > end + 1  # touching ranges are one
    assert held.count() == len(numbers)
    assert held.highest == max(numbers, default=0)
    through = 0
    while through + 1 in numbers:
        through += 1
    assert held.through == through
    missing = {n for first, last in held.missing(250) for n in range(first, last + 1)}
    assert missing == set(range(1, 251)) - numbers
    for n in numbers:
        assert held.end_of(n) in numbers and held.end_of(n) + 1 not in numbers
    above = {n for first, last in held.above(through) for n in range(first, last + 1)}
    assert above == {n for n in numbers if n > through}


def test_end_of_a_number_not_held_is_the_one_before_it() -> None:
    held = SeqRanges([(1, 3), (7, 9)])
    assert held.end_of(5) == 4
    assert held.end_of(8) == 9
    assert held.as_list() == [[1, 3], [7, 9]]
    assert held == SeqRanges([(7, 9), (1, 2), (3, 3)])
