"""codec.encode: compact JSON of exactly the dataclass fields, nested ones included.

The encoder is planned per type (only fields that can hold a list or a
dataclass are converted); the bytes must be what ``dataclasses.asdict`` and
``json.dumps`` give, field order included.
"""

from __future__ import annotations

import dataclasses
import json
import math

import pytest

from shared.contract import Intensity, Prediction, Sample, StickSlipEvent, codec
from shared.errors import InputError

EVENT = StickSlipEvent(
    "st1", 5, 3, 17_000_000_000, 0.5, 120.5, 100.2, 20.3, 30_000.5, 500.2, 0.05, 20.0,
    1.0, 2.0, None, 0.4, 1.2,
    [Prediction(1, 0.55, 125.0, 30_500.0), Prediction(2, 0.6, 130.0, None)],
)  # fmt: skip


@pytest.mark.parametrize(
    "message",
    [
        EVENT,
        dataclasses.replace(EVENT, predictions=[]),
        Intensity("st1", 5, 17_000_000_000, 0.4, 1.2),
        Sample("st1", 1, 2, 3, 4.0, 5.0, None),
    ],
)
def test_encode_is_json_dumps_of_asdict(message: object) -> None:
    expected = json.dumps(dataclasses.asdict(message), separators=(",", ":")).encode()  # type: ignore[call-overload]
    assert codec.encode(message) == expected
    assert codec.decode(type(message), codec.encode(message)) == message


def test_nan_is_written_as_json_nan_and_read_back_where_a_value_may_be_nan() -> None:
    """A sample's measured values may be anything the bus said (the predictor judges them);
    a figure such as an intensity must be finite: the decoder refuses a NaN one."""
    sample = Sample("st1", 1, 2, 3, math.nan, 5.0, math.inf)
    assert b'"torque_nm":NaN' in codec.encode(sample)
    decoded = codec.decode(Sample, codec.encode(sample))
    assert math.isnan(decoded.torque_nm) and decoded.force_n == math.inf
    message = Intensity("st1", 5, 1, math.nan, 1.2)
    assert b'"event_intensity":NaN' in codec.encode(message)
    with pytest.raises(InputError, match="event_intensity is nan, expected a finite number"):
        codec.decode(Intensity, codec.encode(message))


def test_to_dict_nests_predictions() -> None:
    fields = codec.to_dict(EVENT)
    assert fields["predictions"][1] == {
        "horizon": 2,
        "time_s": 0.6,
        "peak_torque_nm": 130.0,
        "plateau_force_n": None,
    }
    assert list(fields) == [f.name for f in dataclasses.fields(StickSlipEvent)]
