"""The rig's frames: a reading beyond its signal's range goes out at full scale."""

from __future__ import annotations

from pathlib import Path

import can
import pytest

from services.rig.frames import RigFrames
from shared.contract import FEATURE_STAGES, StageCommandCode, StationDatabase, ToolStageCode
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


def test_its_tool_stage_and_the_stage_commands_it_reads() -> None:
    database = StationDatabase(DBC_FILE)
    frames = RigFrames(database)
    message = frames.tool_stage(7, ToolStageCode.HOLDING, 1, 2)
    assert (message.arbitration_id, len(message.data)) == (129, 8)
    assert database.decode(message.arbitration_id, message.data) == {
        "RunId": 7, "Stage": 3, "Pulses": 1, "Features": FEATURE_STAGES, "MaxPulses": 2,
    }  # fmt: skip
    command = can.Message(
        arbitration_id=17,
        data=database.encode("StageCommand", {"RunId": 7, "Command": 2, "Pulse": 1, "Reason": 3}),
        is_extended_id=False,
    )
    assert frames.stage_command(command) == (7, StageCommandCode.PULSE)
    unknown = can.Message(arbitration_id=17, data=bytes([7, 0, 0, 0, 9, 0, 0]))
    assert frames.stage_command(unknown) is None  # a command it does not know
    assert frames.stage_command(can.Message(arbitration_id=17, data=b"\x07")) is None  # short
    assert frames.stage_command(message) is None  # not a StageCommand
