"""The rig's frames: a reading beyond its signal's range goes out at full scale."""

from __future__ import annotations

from pathlib import Path

import pytest

from services.rig.frames import RigFrames
from shared.contract import StationDatabase
from tests.support.paths import DBC_FILE


@pytest.mark.parametrize(
    ("torque_nm", "sent_nm"), [(9000.0, 327.67), (-1e9, -327.68), (12.3, 12.3)]
)
def test_a_reading_beyond_the_signal_saturates_instead_of_failing(
    tmp_path: Path, torque_nm: float, sent_nm: float
) -> None:
    """A DBC scaling too narrow for the torque was an OverflowError in the rig."""
    narrow = tmp_path / "narrow.dbc"
    narrow.write_text(
        DBC_FILE.read_text().replace(
            'SG_ Torque : 0|24@1- (0.001,0) [-8388.608|8388.607] "Nm"',
            'SG_ Torque : 0|16@1- (0.01,0) [-327.68|327.67] "Nm"',
        )
    )
    database = StationDatabase(narrow)
    frame = RigFrames(database).tool_sensors(torque_nm, 1.0, 5)
    decoded = database.decode(frame.arbitration_id, frame.data)
    assert decoded["Torque"] == pytest.approx(sent_nm)
