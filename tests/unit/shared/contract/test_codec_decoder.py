"""codec.decoder: the decoder of every message (samples at 1 kHz are its hot path).

It must decode exactly what codec.encode writes, give the same result as
codec.decode on good payloads, and refuse what the JSON schema refuses,
naming the field.
"""

from __future__ import annotations

import json
import math

import pytest

from shared.contract import (
    BusStats,
    Prediction,
    RunSummary,
    Sample,
    StickSlipEvent,
    StopDecision,
    ToolState,
    codec,
)
from shared.errors import InputError

SAMPLE = Sample("st1", 7, 12, 1_700_000_000_000_000_123, 101.5, 33.25, 30_000.0)
decode_sample = codec.decoder(Sample)


def sample_json(**changes: object) -> bytes:
    fields = codec.to_dict(SAMPLE)
    fields.update(changes)
    return json.dumps(fields).encode()


def test_round_trips_what_encode_writes_and_agrees_with_decode() -> None:
    payload = codec.encode(SAMPLE)
    assert decode_sample(payload) == SAMPLE == codec.decode(Sample, payload)
    torque_only = Sample("st1", 7, 13, 5, 1.0, 2.0, None)
    assert decode_sample(codec.encode(torque_only)) == torque_only
    state = ToolState("st2", 8, 3, 1, "running", 9)
    assert codec.decoder(ToolState)(codec.encode(state)) == state


def test_a_number_without_fraction_is_a_number_and_nan_is_kept() -> None:
    assert decode_sample(sample_json(torque_nm=100)).torque_nm == 100
    assert math.isnan(decode_sample(sample_json(force_n=math.nan)).force_n or 0.0)


def test_an_integer_written_with_a_zero_fraction_is_an_integer() -> None:
    """JSON Schema counts 1.0 as an integer (producers such as serde's f64 write it)."""
    decoded = decode_sample(sample_json(run_id=7.0, sequence=12.0))
    assert decoded == SAMPLE and type(decoded.run_id) is int and type(decoded.sequence) is int


def test_whitespace_and_field_order_do_not_matter() -> None:
    fields = codec.to_dict(SAMPLE)
    reordered = dict(reversed(list(fields.items())))
    assert decode_sample(b"  " + json.dumps(reordered, indent=2).encode() + b"\n") == SAMPLE


@pytest.mark.parametrize(
    ("payload", "message"),
    [
        (sample_json(run_id="7"), "run_id is string '7', expected integer"),
        (sample_json(sequence=1.5), "sequence is number 1.5, expected integer"),
        (sample_json(sequence=True), "sequence is boolean True, expected integer"),
        (sample_json(torque_nm=None), "torque_nm is null None, expected integer or number"),
        (sample_json(station=1), "station is integer 1, expected string"),
        (sample_json(force_n=[1.0]), "force_n is array [1.0], expected"),
        (sample_json(extra=1), "unknown field(s) extra"),
        (b'{"station": "st1"}', "missing field(s) run_id, sequence"),
        (b"[1, 2, 3, 4, 5, 6, 7]", "not a valid Sample message"),
        (b'"a string"', "not a JSON object"),
        (codec.encode(SAMPLE)[:-3], "not a valid Sample message"),
        (codec.encode(SAMPLE) + b"{}", "Extra data"),
        (b"\xff\xfe{", "not a valid Sample message"),
        (b"", "not a valid Sample message"),
    ],
)
def test_what_the_schema_refuses_raises_input_error_naming_the_field(
    payload: bytes, message: str
) -> None:
    with pytest.raises(InputError, match="not a valid Sample message") as raised:
        decode_sample(payload)
    assert message in str(raised.value)


def test_enum_fields_take_only_their_values() -> None:
    decode_state = codec.decoder(ToolState)
    good = codec.to_dict(ToolState("st1", 1, 2, 3, "done", 4))
    with pytest.raises(InputError, match="state is 'finished', expected one of 'aborted'"):
        decode_state(json.dumps({**good, "state": "finished"}).encode())
    decision = codec.to_dict(
        StopDecision("st1", 1, 2, 0.5, "plateau_closest", "", 1.0, None, None, 3)
    )
    decode_decision = codec.decoder(StopDecision)
    assert decode_decision(json.dumps(decision).encode()).reason == "plateau_closest"
    with pytest.raises(InputError, match="reason is null None, expected string"):
        decode_decision(json.dumps({**decision, "reason": None}).encode())
    summary = codec.to_dict(
        RunSummary("st1", 1, 2, 3, "done", None, 9.0, None, 8.0, -1.0, 0, None, 0.0, 5, 6, 7)
    )
    decode_summary = codec.decoder(RunSummary)
    assert decode_summary(json.dumps(summary).encode()).stop_reason is None  # optional enum
    with pytest.raises(InputError, match="stop_reason is 'later', expected one of"):
        decode_summary(json.dumps({**summary, "stop_reason": "later"}).encode())


def test_a_missing_field_with_a_default_takes_it() -> None:
    stats = BusStats("st1", 1, 2, 3, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, unsent_samples=0)
    older = codec.to_dict(stats)
    del older["unsent_samples"]  # a publisher from before the field existed
    assert codec.decoder(BusStats)(json.dumps(older).encode()) == stats


def test_one_decoder_for_every_message_nested_ones_too() -> None:
    event = StickSlipEvent(
        "st1",
        1,
        2,
        3,
        0.5,
        10.0,
        9.0,
        1.0,
        None,
        None,
        0.1,
        10.0,
        None,
        None,
        None,
        2.0,
        4.0,
        [Prediction(1, 0.6, 11.0, None)],
    )
    assert codec.decoder(StickSlipEvent)(codec.encode(event)) == event
    fields = codec.to_dict(event)
    fields["predictions"][0]["horizon"] = 1.0  # JSON Schema's integer, inside a nested message
    assert codec.decoder(StickSlipEvent)(json.dumps(fields).encode()) == event
