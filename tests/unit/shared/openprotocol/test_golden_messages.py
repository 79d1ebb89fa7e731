"""Golden wire bytes, written by hand from the public layouts, both ways: encode and decode."""

from __future__ import annotations

from dataclasses import replace

import pytest

from shared.openprotocol import (
    Alarm,
    CommandError,
    CommunicationStart,
    CommunicationStartAck,
    FrameReader,
    LastTighteningResult,
    ToolData,
    decode,
    encode,
)
from tests.support.openprotocol_golden import (
    LAST_RESULT_1,
    LAST_RESULT_1_WIRE,
    LAST_RESULT_2,
    LAST_RESULT_2_WIRE,
    NAME,
    OLD_RESULT_1,
    OLD_RESULT_1_WIRE,
    TOOL_DATA_2,
    TOOL_DATA_2_WIRE,
)

GOLDEN = [
    (CommunicationStart(), b"00200001001         \x00"),
    (CommunicationStart(revision=3), b"00200001003         \x00"),
    (
        CommunicationStartAck(cell_id=1, channel_id=1, controller_name="Airbag1"),
        b"00570002001         010001020103" + NAME.encode() + b"\x00",
    ),
    (CommandError(mid=60, error_code=97), b"00260004001         006097\x00"),
    (CommandError(mid=1, error_code=96, revision=2), b"00270004002         0001096\x00"),
    (LAST_RESULT_1, LAST_RESULT_1_WIRE),
    (LAST_RESULT_2, LAST_RESULT_2_WIRE),
    (OLD_RESULT_1, OLD_RESULT_1_WIRE),
    (TOOL_DATA_2, TOOL_DATA_2_WIRE),
    (
        Alarm(
            error_code="E851", controller_ready=True, tool_ready=False, time="2024-06-01:07:31:02"
        ),
        b"00530071001         01E851021030042024-06-01:07:31:02\x00",
    ),
]


@pytest.mark.parametrize(("message", "wire"), GOLDEN, ids=lambda v: type(v).__name__)
def test_golden_bytes_encode_and_decode(message: object, wire: bytes) -> None:
    assert encode(message) == wire  # type: ignore[arg-type]
    (frame,) = FrameReader().feed(wire)
    assert frame.revision == message.revision  # type: ignore[attr-defined]
    assert decode(frame) == message
    assert int(wire[:4]) == len(wire) - 1  # the length excludes the NUL


def test_result_lengths_are_the_specifications() -> None:
    assert len(LAST_RESULT_1_WIRE) - 1 == 231
    assert len(LAST_RESULT_2_WIRE) - 1 == 385
    assert len(OLD_RESULT_1_WIRE) - 1 == 118


@pytest.mark.parametrize(
    ("torque_nm", "sent_nm"),
    [(12.349, 12.34), (12.345, 12.34), (0.29, 0.29), (1.1, 1.1), (9999.999, 9999.99)],
)
def test_a_torque_is_sent_with_two_decimals_truncated_as_the_specification_says(
    torque_nm: float, sent_nm: float
) -> None:
    """R2.8.0, 0061 parameters 12-15 (and 0041, 0065): "multiplied by 100 and sent as an
    integer (2 decimals truncated)". Before: rounded, 12.349 Nm went out as 12.35 Nm."""
    sent = replace(LAST_RESULT_1, torque_nm=torque_nm, torque_max_nm=torque_nm)
    (frame,) = FrameReader().feed(encode(sent))
    read = decode(frame)
    assert isinstance(read, LastTighteningResult)
    assert (read.torque_nm, read.torque_max_nm) == (sent_nm, sent_nm)
    (frame,) = FrameReader().feed(encode(replace(TOOL_DATA_2, calibration_value_nm=torque_nm)))
    tool = decode(frame)
    assert isinstance(tool, ToolData) and tool.calibration_value_nm == sent_nm
