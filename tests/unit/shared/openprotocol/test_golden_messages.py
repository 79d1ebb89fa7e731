"""Golden wire bytes, written by hand from the public layouts, both ways: encode and decode."""

from __future__ import annotations

import pytest

from shared.openprotocol import (
    Alarm,
    CommandError,
    CommunicationStart,
    CommunicationStartAck,
    FrameReader,
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
