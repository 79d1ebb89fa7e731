"""Malformed or out-of-range content: one OpenProtocolError, one exact line each."""

from __future__ import annotations

import dataclasses
import datetime as dt

import pytest

from shared.errors import InputError
from shared.openprotocol import (
    CommandError,
    Frame,
    LastTighteningResult,
    OpenProtocolError,
    TraceCurve,
    WireMessage,
    decode,
    encode,
    format_timestamp,
    timestamp_ns,
    trace_extra_data,
)
from tests.support.openprotocol_examples import TRACE
from tests.support.openprotocol_golden import (
    ASCII_PART,
    BIG,
    LAST_RESULT_1,
    LAST_RESULT_1_WIRE,
    LAST_RESULT_2,
    LAST_RESULT_2_WIRE,
)


def _data(wire: bytes) -> bytes:
    return wire[20:-1]


def _refusal_of_data(mid: int, revision: int, data: bytes) -> str:
    with pytest.raises(OpenProtocolError) as refused:
        decode(Frame(mid=mid, revision=revision, data=data))
    assert isinstance(refused.value, InputError)
    return str(refused.value)


REV2 = _data(LAST_RESULT_2_WIRE)
REV1 = _data(LAST_RESULT_1_WIRE)

DECODE_REFUSALS = [
    (61, 2, REV2.replace(b"24001480", b"2400A123"),
     "MID 0061 rev 2, field 'torque final': '00A123' is not a number"),
    (61, 2, REV2.replace(b"24001480", b"24-01480"),
     "MID 0061 rev 2, field 'torque final': '-01480' is not a number"),
    (61, 1, REV1.replace(b"070000", b"07-001"),
     "MID 0061 rev 1, field 'batch size': '-001' is not a number"),
    (61, 1, REV1.replace(b"202001-06-02", b"202001-02-30"),
     "MID 0061 rev 1, field 'timestamp': '2001-02-30:09:54:09' is not a date and time that exists"),
    (61, 1, REV1.replace(b"090", b"092"),
     "MID 0061 rev 1, field 'tightening status': '2' is not in [0, 1]"),
    (61, 1, REV1.replace(b"101111", b"107111"),
     "MID 0061 rev 1, field 'torque status': '7' is not one of 0 LOW, 1 OK, 2 HIGH"),
    (61, 1, REV1.replace(b"12000120", b"XX000120"),
     "MID 0061 rev 1, field 'torque min limit': parameter id 'XX' where 12 is due"),
    (61, 2, REV2[:-5],
     "MID 0061 rev 2, field 'date/time of last change in parameter set settings': "
     "data ends at byte 360, the field needs 21 from 344"),
    (4, 1, b"00609",
     "MID 0004 rev 1, field 'error code': data ends at byte 5, the field needs 2 from 4"),
    (8, 1, b"0900001" b"41" b"000",
     "MID 0008 rev 1, field 'extra data': 3 bytes where the extra data length says 41"),
    (900, 1, ASCII_PART + b"\x00" + BIG[:-2],
     "MID 0900 rev 1, field 'trace samples': 5 bytes where 3 samples need 6 (+ 1 NUL)"),
    (900, 1, ASCII_PART.replace(b"02214", b"02000") + b"\x00" + BIG,
     "MID 0900 rev 1, field 'parameter data fields': "
     "no coefficient (02214) or divisor (02213) parameter"),
    (900, 1, ASCII_PART.replace(b"0.01", b"-.01") + b"\x00" + BIG,
     "MID 0900 rev 1, field 'parameter 02214 value': '-.01' is not a positive number"),
    (900, 1, ASCII_PART.replace(b"202", b"204") + b"\x00" + BIG,
     "MID 0900 rev 1, field 'resolution unit': 204 is not a time unit (200, 201, 202, 203)"),
    (900, 1, ASCII_PART[:40],
     "MID 0900 rev 1, field 'number of parameter data fields': "
     "data ends at byte 40, the field needs 3 from 39"),
]  # fmt: skip


@pytest.mark.parametrize(("mid", "revision", "data", "line"), DECODE_REFUSALS)
def test_decode_refuses_with_one_line(mid: int, revision: int, data: bytes, line: str) -> None:
    assert _refusal_of_data(mid, revision, data) == line


ENCODE_REFUSALS: list[tuple[WireMessage, str]] = [
    (dataclasses.replace(LAST_RESULT_1, torque_nm=1e12),
     "MID 0061 rev 1, field 'torque final': 1000000000000.0 is not in [0, 9999.99]"),
    (dataclasses.replace(LAST_RESULT_1, torque_nm=-1.0),
     "MID 0061 rev 1, field 'torque final': -1.0 is not in [0, 9999.99]"),
    (dataclasses.replace(LAST_RESULT_1, torque_nm=float("nan")),
     "MID 0061 rev 1, field 'torque final': nan is not a number"),
    (dataclasses.replace(LAST_RESULT_1, batch_counter=-1),
     "MID 0061 rev 1, field 'batch counter': -1 is not in [0, 9999]"),
    (dataclasses.replace(LAST_RESULT_1, job_id=100),
     "MID 0061 rev 1, field 'job id': 100 is not in [0, 99]"),
    (dataclasses.replace(LAST_RESULT_1, timestamp="2024-13-01:00:00:00"),
     "MID 0061 rev 1, field 'timestamp': '2024-13-01:00:00:00' is not a date and time that exists"),
    (dataclasses.replace(LAST_RESULT_1, vin="x" * 26),
     f"MID 0061 rev 1, field 'vin number': '{'x' * 26}' is longer than 25 characters"),
    (dataclasses.replace(LAST_RESULT_2, angle_deg=1.5),  # type: ignore[arg-type]
     "MID 0061 rev 2, field 'angle final': 1.5 is not a whole number"),
    (dataclasses.replace(TRACE, samples=(82.0,)),
     "MID 0900 rev 1, field 'trace samples': 82.0 is not in [-81.92, 81.9175] "
     "(16 bits at coefficient 0.0025)"),
]  # fmt: skip


@pytest.mark.parametrize(("message", "line"), ENCODE_REFUSALS)
def test_encode_refuses_with_one_line(message: WireMessage, line: str) -> None:
    with pytest.raises(OpenProtocolError) as refused:
        encode(message)
    assert str(refused.value) == line


def test_a_revision_lacking_fields_is_refused_when_encoded_at_a_higher_one() -> None:
    with pytest.raises(OpenProtocolError) as refused:
        encode(LAST_RESULT_1, revision=2)
    assert str(refused.value) == "MID 0061 rev 2, field 'strategy': is needed by revision 2"
    decoded = decode(Frame(mid=61, revision=1, data=REV1))
    assert isinstance(decoded, LastTighteningResult) and decoded.strategy is None


def test_error_codes_have_names() -> None:
    assert CommandError(mid=1, error_code=97).error_name == "MID_REVISION_UNSUPPORTED"
    assert CommandError(mid=1, error_code=250).error_name == "error 250"


def test_trace_subscription_refuses_impossible_requests() -> None:
    with pytest.raises(OpenProtocolError) as refused:
        trace_extra_data([])
    assert str(refused.value) == (
        "MID 0008, field 'extra data': trace types [] are not 1 to 99 numbers of 1..999"
    )


def test_timestamps_become_ns_since_the_epoch_in_the_controllers_zone() -> None:
    assert timestamp_ns("1970-01-01:00:00:01") == 1_000_000_000
    cet = dt.timezone(dt.timedelta(hours=1))
    assert timestamp_ns("1970-01-01:01:00:01", cet) == 1_000_000_000
    assert format_timestamp(1_000_000_000, cet) == "1970-01-01:01:00:01"
    with pytest.raises(ValueError, match="is not a date and time that exists"):
        timestamp_ns("2023-02-29:00:00:00")
    assert isinstance(TRACE, TraceCurve)
