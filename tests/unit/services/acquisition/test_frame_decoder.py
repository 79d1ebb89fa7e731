"""Frame decoding against the station DBC: contract frames and every kind of garbage."""

from hypothesis import given, settings
from hypothesis import strategies as st

from services.acquisition.frame_decoder import (
    FrameDecoder,
    JointSensorsFrame,
    Rejected,
    ToolSensorsFrame,
    ToolStatusFrame,
)
from shared.contract import SpindleIds, StationDatabase
from tests.support.paths import DBC_FILE

DATABASE = StationDatabase(DBC_FILE)
DECODER = FrameDecoder(SpindleIds(DATABASE))


def test_tool_sensors_round_trip_with_dbc_resolution() -> None:
    data = DATABASE.encode("ToolSensors", {"Torque": 187.4321, "Angle": -3.14, "Counter": 9})
    frame = DECODER.decode(DATABASE.tool_sensors_id, data)
    assert isinstance(frame, ToolSensorsFrame)
    assert frame.counter == 9
    assert abs(frame.torque_nm - 187.432) < 1e-3
    assert abs(frame.angle_deg + 3.14) < 1e-2


def test_joint_sensors_and_tool_status() -> None:
    data = DATABASE.encode("JointSensors", {"Force": 56123.4, "Counter": 65535})
    frame = DECODER.decode(DATABASE.joint_sensors_id, data)
    assert isinstance(frame, JointSensorsFrame)
    assert frame.counter == 65535 and abs(frame.force_n - 56123.4) < 0.06
    status = DATABASE.encode("ToolStatus", {"RunId": 4711, "ToolId": 7, "ProgramId": 2, "State": 1})
    assert DECODER.decode(DATABASE.tool_status_id, status) == ToolStatusFrame(4711, 7, 2, 1)


def test_rejects_unknown_ids_wrong_lengths_error_and_remote_frames() -> None:
    assert DECODER.decode(0x7FF, bytes(8)) == Rejected("unknown_id")
    assert DECODER.decode(DATABASE.tool_sensors_id, bytes(7)) == Rejected("wrong_length")
    assert DECODER.decode(DATABASE.tool_sensors_id, bytes(8), is_error_frame=True) == Rejected(
        "error_frame"
    )
    assert DECODER.decode(DATABASE.tool_sensors_id, b"", is_remote_frame=True) == Rejected(
        "remote_frame"
    )


@settings(max_examples=500, deadline=None)
@given(st.integers(min_value=0, max_value=0x1FFFFFFF), st.binary(max_size=64))
def test_no_frame_makes_the_decoder_raise(arbitration_id: int, data: bytes) -> None:
    frame = DECODER.decode(arbitration_id, data)
    if arbitration_id not in DATABASE.by_id:
        assert frame == Rejected("unknown_id")
    elif len(data) != DATABASE.by_id[arbitration_id][1]:
        assert frame == Rejected("wrong_length")
    else:
        assert not isinstance(frame, Rejected) or frame.reason == "decode_error"
