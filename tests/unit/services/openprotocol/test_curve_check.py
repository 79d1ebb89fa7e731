"""Curves are read the way that agrees with their result, or refused: never recorded wrong."""

from __future__ import annotations

import struct

import pytest

from services.openprotocol.controller_tightening import Curve, ResultFigures, Tightening
from services.openprotocol.curve_check import Reading, check_curves, readings

FINAL_TORQUE_NM = 25.0
FINAL_ANGLE_DEG = 180.0
COEFFICIENT = 0.01
SAMPLES = 500


def result(torque_nm: float = FINAL_TORQUE_NM, angle_deg: float = FINAL_ANGLE_DEG) -> ResultFigures:
    return ResultFigures(
        tightening_id=7,
        program_id=1,
        time_ns=1_795_000_000_000_000_000,
        ok=True,
        torque_nm=torque_nm,
        torque_min_nm=20.0,
        torque_max_nm=30.0,
        torque_target_nm=25.0,
        angle_deg=angle_deg,
        angle_min_deg=None,
        angle_max_deg=None,
        angle_target_deg=None,
        part_id="",
        batch_size=None,
        batch_counter=None,
        strategy="",
        revision=2,
        filled=False,
    )


def curve(
    kind: str, values: list[float], order: str = ">", coefficient: float = COEFFICIENT
) -> Curve:
    """A curve as it came: its samples packed in ``order``, read big-endian as the codec does."""
    raw = [round(value / coefficient) for value in values]
    data = struct.pack(f"{order}{len(raw)}h", *raw)
    as_read = struct.unpack(f">{len(raw)}h", data)
    return Curve(
        7,
        kind,
        1_795_000_000_000_000_000,
        0.001,
        tuple(value * coefficient for value in as_read),
        data,
        coefficient,
    )


def ramp(final: float) -> list[float]:
    """A ramp to ``final`` with stick-slip drops every 50 samples."""
    return [final * i / (SAMPLES - 1) - (0.5 if 40 < i % 50 < 46 else 0.0) for i in range(SAMPLES)]


def tightening(order: str = ">", coefficient: float = COEFFICIENT) -> Tightening:
    return Tightening(
        result(),
        curve("torque", ramp(FINAL_TORQUE_NM), order, coefficient),
        curve("angle", ramp(FINAL_ANGLE_DEG), order, coefficient),
    )


def test_big_endian_samples_agree_as_they_are_read() -> None:
    checked = check_curves(tightening(">"), readings("auto"))
    assert checked.reading == Reading("big")
    assert checked.refused == ()
    assert checked.torque is not None and max(checked.torque.values) == pytest.approx(25.0)


def test_little_endian_samples_are_found_and_read_right() -> None:
    """Read big-endian, a 25 Nm tightening peaks at hundreds of Nm: the little-endian
    reading is the one that agrees."""
    wrong = tightening("<")
    assert wrong.torque is not None and max(wrong.torque.values) > 100.0
    checked = check_curves(wrong, readings("auto"))
    assert checked.reading == Reading("little")
    assert checked.torque is not None and checked.angle is not None
    assert max(checked.torque.values) == pytest.approx(25.0)
    assert checked.angle.values[-1] == pytest.approx(180.0)


def test_a_scaling_meant_the_other_way_is_found() -> None:
    """A controller that sends the divisor 100 as its coefficient (value = raw * 100)."""
    inverted = tightening(">")
    as_sent = Tightening(
        inverted.result,
        *(
            Curve(c.tightening_id, c.kind, c.start_ns, c.time_step_s, (), c.sample_bytes, 100.0)
            for c in (inverted.torque, inverted.angle)
            if c is not None
        ),
    )
    checked = check_curves(as_sent, readings("auto"))
    assert checked.reading == Reading("big", inverted_scale=True)
    assert checked.torque is not None and max(checked.torque.values) == pytest.approx(25.0)


def test_a_configured_byte_order_refuses_curves_of_the_other() -> None:
    checked = check_curves(tightening("<"), readings("big"))
    assert checked.reading is None
    assert checked.torque is None and checked.angle is None
    assert len(checked.refused) == 2 and "agrees with its result read no way" in checked.refused[0]


def test_a_curve_that_agrees_with_no_reading_is_refused() -> None:
    """A torque curve whose peak is twice the result's final torque: refused; its angle
    curve agrees, read big-endian, and is kept."""
    doubled = Tightening(
        result(torque_nm=12.5),
        curve("torque", ramp(FINAL_TORQUE_NM)),
        curve("angle", ramp(FINAL_ANGLE_DEG)),
    )
    checked = check_curves(doubled, readings("auto"))
    assert checked.torque is None
    assert checked.angle is not None
    assert checked.reading == Reading("big")
    assert len(checked.refused) == 1 and "its peak 25 Nm" in checked.refused[0]


def test_an_angle_curve_counted_from_before_the_final_step_agrees() -> None:
    """A trace whose angle counts from the rundown: it ends far beyond the final angle,
    rising all the way; read the wrong way it jumps up and down and is refused."""
    rundown = [3000.0 * i / (SAMPLES - 1) for i in range(SAMPLES)]
    kept = check_curves(
        Tightening(result(), None, curve("angle", rundown, coefficient=0.1)), readings("auto")
    )
    assert kept.reading == Reading("big") and kept.refused == ()
    jumping = check_curves(
        Tightening(result(), None, curve("angle", rundown, "<", coefficient=0.1)),
        readings("big"),
    )
    assert jumping.angle is None and len(jumping.refused) == 1


def test_a_result_without_finals_leaves_its_curves_unchecked() -> None:
    unchecked = Tightening(result(torque_nm=0.0, angle_deg=0.0), curve("torque", ramp(9.0)), None)
    checked = check_curves(unchecked, readings("auto"))
    assert checked.reading is None and checked.refused == ()
    assert checked.torque is not None and max(checked.torque.values) == pytest.approx(9.0)


def test_a_reading_is_kept_as_text_and_read_back() -> None:
    for reading in readings("auto"):
        assert Reading.parse(reading.text) == reading
    assert Reading.parse("") is None and Reading.parse("middle") is None
