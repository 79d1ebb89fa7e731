"""A multi-spindle station's file: its spindles, their tools and their CAN ids, each mistake one
line naming the file and the key."""

from __future__ import annotations

from pathlib import Path

import pytest

from shared.config import load_station
from shared.errors import ConfigError
from tests.support.paths import DBC_FILE
from tests.support.station_files import write_station

FORCE = "has_force_sensor = true"


def test_a_station_is_of_one_spindle_unless_its_file_says_more(tmp_path: Path) -> None:
    for name in "abc":
        (tmp_path / name).mkdir()
    single = load_station(write_station(tmp_path / "a")).config
    assert (single.station.spindles, single.station.tool_of(None)) == (1, 7)
    four = load_station(
        write_station(tmp_path / "b", replacements={FORCE: f"{FORCE}\nspindles = 4"})
    )
    assert [four.config.station.tool_of(k) for k in (1, 2, 3, 4)] == [7, 8, 9, 10]
    named = load_station(
        write_station(
            tmp_path / "c",
            replacements={FORCE: f"{FORCE}\nspindles = 2\nspindle_tool_ids = [31, 12]"},
        )
    )
    assert [named.config.station.tool_of(k) for k in (1, 2)] == [31, 12]


@pytest.mark.parametrize(
    ("station", "can", "expected"),
    [
        ("spindles = 3\nspindle_tool_ids = [1, 2]", "", "names 2 tools for 3 spindles"),
        ("spindles = 2\nspindle_tool_ids = [5, 5]", "", "an id twice"),
        ("spindles = 0", "", r"station.spindles: .*greater than or equal to 1"),
        ("spindles = 4", "spindle_id_stride = 1", "can.spindle_id_stride: .* share id 0x101"),
    ],
)
def test_a_spindle_mistake_is_one_line_naming_file_and_key(
    tmp_path: Path, station: str, can: str, expected: str
) -> None:
    path = write_station(
        tmp_path,
        replacements={FORCE: f"{FORCE}\n{station}", 'dbc = "': f'{can}\ndbc = "'},
    )
    with pytest.raises(ConfigError, match=expected) as raised:
        load_station(path)
    assert str(path) in str(raised.value) and "\n" not in str(raised.value)


def test_several_spindles_need_the_dbcs_cycle_start(tmp_path: Path) -> None:
    dbc = tmp_path / "old.dbc"
    dbc.write_text(DBC_FILE.read_text().replace("BO_ 96 CycleStart", "BO_ 96 CycleStarz"))
    path = write_station(
        tmp_path,
        replacements={FORCE: f"{FORCE}\nspindles = 2", f'"{DBC_FILE}"': f'"{dbc}"'},
    )
    with pytest.raises(ConfigError, match="2 spindles need the DBC's CycleStart"):
        load_station(path)
    (tmp_path / "one").mkdir()
    single = write_station(tmp_path / "one", replacements={f'"{DBC_FILE}"': f'"{dbc}"'})
    assert load_station(single).config.station.spindles == 1  # a DBC of before: as before
