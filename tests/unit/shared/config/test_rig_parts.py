"""``[rig] bolts_per_part`` and ``part_pattern``: the simulated line's parts and their ids."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from shared.config import RigSection
from shared.contract import PART_ID, PART_ID_CHARS


def test_by_default_four_bolts_per_part_named_by_the_station_and_its_first_run() -> None:
    rig = RigSection()
    assert rig.bolts_per_part == 4
    assert rig.part_id("st1", 1000) == "st1-P001000"
    assert rig.part_id("st1", 1_718_000_000) == "st1-P1718000000"
    widest = rig.part_id("s" * 64, 2**32 - 1)
    assert len(widest) <= PART_ID_CHARS and PART_ID.fullmatch(widest)


def test_a_pattern_may_make_vin_like_ids() -> None:
    rig = RigSection(part_pattern="WBOLT{first_run_id:012d}", bolts_per_part=1)
    assert rig.part_id("st1", 4711) == "WBOLT000000004711"


@pytest.mark.parametrize(
    ("pattern", "error"),
    [
        ("{station}-{tool_id}", "names 'tool_id'; expected only station, first_run_id"),
        ("{station}-{first_run_id:d", "not a format text"),
        (
            "{station}{station}-P{first_run_id}",
            "131 characters at its widest; a part id has at most 100",
        ),
        ("{first_run_id:>12}", "a part id is printable ASCII, no space at either end"),
        ("Teil-{first_run_id}", None),  # plain ASCII: fine
        ("Teil-Ü{first_run_id}", "a part id is printable ASCII"),
        ("", "a part id is printable ASCII"),
    ],
)
def test_a_pattern_that_could_make_a_bad_part_id_is_refused(
    pattern: str, error: str | None
) -> None:
    if error is None:
        assert RigSection(part_pattern=pattern).part_pattern == pattern
        return
    with pytest.raises(ValidationError, match="part_pattern") as raised:
        RigSection(part_pattern=pattern)
    assert error in str(raised.value)


@pytest.mark.parametrize("bolts", [-1, 10_001])
def test_bolts_per_part_is_bounded_and_zero_means_no_parts(bolts: int) -> None:
    assert RigSection(bolts_per_part=0).bolts_per_part == 0
    with pytest.raises(ValidationError, match="bolts_per_part"):
        RigSection(bolts_per_part=bolts)
