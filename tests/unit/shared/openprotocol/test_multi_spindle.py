"""Multi-spindle status and result (0091, 0101) refuse what the specification does not allow,
naming the field: a spindle list shorter than its count, a parameter id out of place, a
spindle numbered 00, a negative angle below revision 4 (a press's stroke may be negative from
revision 4 on)."""

from __future__ import annotations

import pytest

from shared.openprotocol import (
    Frame,
    MultiSpindleResult,
    OpenProtocolError,
    SpindleResult,
    decode,
    encode,
)
from tests.support.openprotocol_examples import MULTI_SPINDLE_RESULT

#: OpenProtocolInterpreter's 0101 revision 1 test message (tests/data/openprotocol/examples)
DATA_0101 = (
    b"010202BM3GA02111900601         030304003050001060001071080006800900092010000800110000012"
    b"000151300000142019-11-14:14:08:05152019-11-25:11:22:411600913171180101110008091000000201"
    b"11000809100000"
)


def _decoded(data: bytes, revision: int = 1) -> object:
    return decode(Frame(mid=101, revision=revision, data=data))


def test_the_example_reads_by_the_specifications_offsets() -> None:
    message = _decoded(DATA_0101)
    assert isinstance(message, MultiSpindleResult)
    # bytes 21-22 "01", 23-24 the spindles (02); 165-169 the sync id; 175 on the spindles
    wire = encode(message)
    assert (
        wire[22:24] == b"02" and wire[164:169] == b"00913" and wire[174:192] == DATA_0101[154:172]
    )
    assert [s.spindle for s in message.spindles] == [1, 2]


@pytest.mark.parametrize(
    ("data", "field"),
    [
        (DATA_0101[:-18], "spindle status"),  # two spindles said, one listed
        (DATA_0101[:152] + b"19" + DATA_0101[154:], "spindle status"),  # parameter id 19 for 18
        (DATA_0101[:154] + b"00" + DATA_0101[156:], "spindle number"),  # spindle 00
        (DATA_0101[:167] + b"-0001", "spindle angle"),  # negative angle, revision 1
        (DATA_0101[:2] + b"00" + DATA_0101[4:], "number of spindles"),  # no spindle
    ],
)
def test_a_0101_out_of_the_specification_is_refused_naming_the_field(
    data: bytes, field: str
) -> None:
    with pytest.raises(OpenProtocolError) as refused:
        _decoded(data)
    assert refused.value.field == field


def test_a_press_stroke_below_zero_is_read_and_written_from_revision_4() -> None:
    press = MULTI_SPINDLE_RESULT.__class__(
        **{
            **{name: getattr(MULTI_SPINDLE_RESULT, name) for name in ("vin", "job_id", "pset_id")},
            "batch_size": 1, "batch_counter": 1,
            "batch_status": MULTI_SPINDLE_RESULT.batch_status, "torque_min_nm": 1.0,
            "torque_max_nm": 2.0, "torque_final_target_nm": 1.5, "angle_min_deg": -15,
            "angle_max_deg": 10, "angle_final_target_deg": 0,
            "pset_changed": MULTI_SPINDLE_RESULT.pset_changed,
            "timestamp": MULTI_SPINDLE_RESULT.timestamp, "sync_tightening_id": 1, "ok": True,
            "spindles": (SpindleResult(1, 1, True, 1, 1.25, True, -15),),
            "system_sub_type": 2, "revision": 4,
        }
    )  # fmt: skip
    wire = encode(press)
    assert b"11-0015" in wire
    assert decode(Frame(mid=101, revision=4, data=wire[20:-1])) == press
    with pytest.raises(OpenProtocolError, match="angle"):
        encode(press, revision=3)
