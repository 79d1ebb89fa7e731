"""0900 trace curves: golden bytes, scaling, time step, byte order and NUL variants."""

from __future__ import annotations

import dataclasses

import pytest

from shared.openprotocol import (
    DEFAULT_DIALECT,
    DataSubscribe,
    Dialect,
    Frame,
    FrameReader,
    ResolutionField,
    TraceCurve,
    TraceType,
    VariableField,
    decode,
    encode,
    trace_extra_data,
    trace_types_of,
)
from tests.support.openprotocol_golden import ASCII_PART, BIG, LITTLE, TRACE_WIRE


def _trace(data: bytes, dialect: Dialect = DEFAULT_DIALECT) -> TraceCurve:
    message = decode(Frame(mid=900, data=data), dialect=dialect)
    assert isinstance(message, TraceCurve)
    return message


def test_golden_0900_decodes_to_samples_in_their_unit_and_the_step_in_seconds() -> None:
    (frame,) = FrameReader().feed(TRACE_WIRE)
    (with_nul,) = FrameReader().feed(TRACE_WIRE + b"\x00")  # as some controllers send it
    assert with_nul == frame
    trace = decode(frame)
    assert isinstance(trace, TraceCurve)
    assert (trace.result_id, trace.timestamp) == (345, "2024-06-01:07:31:02")
    assert (trace.trace_type, trace.transducer_type, trace.unit) == (TraceType.TORQUE, 1, 1)
    assert trace.samples == pytest.approx((1.0, -0.5, 12.34))
    assert trace.coefficient == 0.01
    assert trace.time_step_s == pytest.approx(0.001)
    assert encode(trace) == TRACE_WIRE


def test_samples_are_read_and_written_in_either_byte_order() -> None:
    little = Dialect(trace_byte_order="little")
    big_trace = _trace(ASCII_PART + b"\x00" + BIG)
    little_trace = _trace(ASCII_PART + b"\x00" + LITTLE, little)
    assert little_trace == big_trace
    assert encode(big_trace, dialect=little) == TRACE_WIRE.replace(BIG, LITTLE)
    # The same bytes read with the wrong order give other values: the setting matters.
    assert _trace(ASCII_PART + b"\x00" + BIG, little).samples != big_trace.samples


def test_the_nul_before_the_samples_may_be_missing_or_a_nul_after_them_counted() -> None:
    expected = _trace(ASCII_PART + b"\x00" + BIG)
    assert _trace(ASCII_PART + BIG) == expected
    assert _trace(ASCII_PART + b"\x00" + BIG + b"\x00") == expected
    without = encode(expected, dialect=Dialect(trace_nul_separator=False))
    assert without == b"01160900001         " + ASCII_PART + BIG


def test_a_divisor_parameter_divides() -> None:
    divided = ASCII_PART.replace(b"02214004030000000" + b"0.01", b"02213003030000000" + b"100")
    trace = _trace(divided + b"\x00" + BIG)
    assert trace.samples == pytest.approx((1.0, -0.5, 12.34))
    assert trace.coefficient == 0.01
    assert encode(trace)[20:] == divided + b"\x00" + BIG


def test_build_makes_a_curve_that_reads_back() -> None:
    trace = TraceCurve.build(
        result_id=7, timestamp="2024-06-01:07:31:02", trace_type=TraceType.ANGLE, unit=50,
        samples=(0.0, 0.5, 1.0), time_step_s=0.001, coefficient=0.5,
    )  # fmt: skip
    assert (trace.coefficient, trace.time_step_s) == (0.5, 0.001)
    (frame,) = FrameReader().feed(encode(trace))
    assert decode(frame) == trace


def test_several_pid_and_resolution_fields_are_kept() -> None:
    trace = dataclasses.replace(
        _trace(ASCII_PART + b"\x00" + BIG),
        pid_fields=(VariableField(1, "abc", 4), VariableField(30, "")),
        resolution_fields=(ResolutionField(1, 2, "0.5", 202), ResolutionField(3, 3, "2", 202)),
    )
    (frame,) = FrameReader().feed(encode(trace))
    assert decode(frame) == trace
    assert trace.time_step_s == 0.0005


def test_the_0900_subscription_asks_trace_types_new_or_from_a_result_id() -> None:
    extra = trace_extra_data([TraceType.ANGLE, TraceType.TORQUE, TraceType.CURRENT])
    assert extra == "0" + "0" * 19 + "0" * 10 + "03" + "001002003"  # send alternative 0
    assert trace_types_of(extra) == (1, 2, 3)
    from_345 = trace_extra_data([TraceType.TORQUE], from_result_id=345)
    assert from_345 == "1" + "0" * 19 + "0000000345" + "01" + "002"  # send alternative 1
    assert trace_types_of(from_345) == (2,)
    assert trace_types_of("3" + "0000000001" + "0000000009" + "01001") == (1,)
    subscribe = DataSubscribe(mid=900, wanted_revision=1, extra_data=extra)
    assert encode(subscribe) == b"00700008001         090000141" + extra.encode() + b"\x00"
