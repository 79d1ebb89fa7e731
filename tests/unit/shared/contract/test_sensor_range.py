"""The sensor range: what a station's DBC signals can carry, and the contract's default."""

from __future__ import annotations

from pathlib import Path

import pytest

from shared.config import load_station
from shared.contract import CONTRACT_RANGE, SensorRange, StationDatabase
from tests.support.paths import DBC_FILE, STATION_FILE


def test_the_contract_range_is_the_shipped_dbc() -> None:
    assert SensorRange.of_database(StationDatabase(DBC_FILE)) == CONTRACT_RANGE


def test_a_station_takes_the_range_of_its_dbc() -> None:
    assert load_station(STATION_FILE).sensor_range == CONTRACT_RANGE


def test_a_narrower_dbc_gives_a_narrower_range(tmp_path: Path) -> None:
    """A 16-bit torque at 0.01 Nm with a stated range of 0..300 Nm."""
    text = DBC_FILE.read_text().replace(
        'SG_ Torque : 0|24@1- (0.001,0) [-8388.608|8388.607] "Nm"',
        'SG_ Torque : 0|16@1- (0.01,0) [0|300] "Nm"',
    )
    narrow = tmp_path / "narrow.dbc"
    narrow.write_text(text)
    assert SensorRange.of_database(StationDatabase(narrow)).torque_nm == (0.0, 300.0)


@pytest.mark.parametrize("bounds", [(1.0, 1.0), (2.0, 1.0), (0.0, float("inf"))])
def test_a_range_must_be_finite_and_ordered(bounds: tuple[float, float]) -> None:
    with pytest.raises(ValueError, match="torque_nm"):
        SensorRange(torque_nm=bounds, angle_deg=(0.0, 1.0), force_n=(0.0, 1.0))
