"""A recording's name read back (``file_name_of``): what ``file_path`` wrote, and nothing else."""

from __future__ import annotations

from datetime import UTC, datetime
from pathlib import Path

import pytest

from shared.recordings import file_name_of, file_path

OPENED_NS = 1_700_000_000_123_456_789  # 2023-11-14 22:13:20 UTC


@pytest.mark.parametrize(("run_id", "part"), [(42, 1), (42, 3), (None, 1), (2**40, 2)])
def test_a_name_file_path_gives_reads_back(tmp_path: Path, run_id: int | None, part: int) -> None:
    path = file_path(tmp_path, "st-1_a", run_id, OPENED_NS, part)
    name = file_name_of(path, "st-1_a")
    assert name is not None
    assert (name.run_id, name.part, name.copy) == (run_id, part, 1)
    assert name.opened == datetime(2023, 11, 14, 22, 13, 20, tzinfo=UTC)


def test_a_copy_reads_back_and_sorts_after_the_first(tmp_path: Path) -> None:
    first = file_path(tmp_path, "st1", 7, OPENED_NS)
    first.parent.mkdir(parents=True)
    first.write_bytes(b"")
    second = file_path(tmp_path, "st1", 7, OPENED_NS)
    assert second.name == "st1_run7_221320_2.mcap"
    names = [file_name_of(path, "st1") for path in (first, second)]
    assert [name.copy for name in names if name] == [1, 2]
    assert names[0] and names[1] and names[0].order < names[1].order


@pytest.mark.parametrize(
    "name",
    [
        "st10_run7_221320.mcap",  # another station's
        "st1_run7_221320.rrd",
        "st1_run7_2213.mcap",
        "st1_runX_221320.mcap",
        "st1_run7_221320.recovered.mcap",
        "st1_run7_251320.mcap",  # no such time
    ],
)
def test_other_names_are_none(name: str) -> None:
    assert file_name_of(Path("/r/st1/2023-11-14") / name, "st1") is None


def test_a_day_folder_that_is_no_day_is_none() -> None:
    assert file_name_of(Path("/r/st1/copies/st1_run7_221320.mcap"), "st1") is None
