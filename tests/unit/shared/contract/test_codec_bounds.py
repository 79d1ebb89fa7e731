"""Every field of every message is bounded: the decoders refuse the rest, the schemas say so.

The bounds are declared once (shared/contract/message_fields.py) and hold for both
decoders (``codec.decoder`` of flat messages, ``codec.decode`` of any), for
payload size and nesting depth too; every refusal is an InputError naming
the field, never another exception.
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from collections.abc import Callable

import jsonschema
import pytest

from shared.contract import (
    CHANNELS,
    MAX_TEXT_CHARS,
    SCHEMA_TYPES,
    ControllerResult,
    RunSummary,
    Sample,
    SampleBatch,
    StickSlipEvent,
    StopDecision,
    ToolState,
    codec,
)
from shared.errors import InputError
from tests.support.fuzz.payloads import extreme_values, refused_values, template

NOW_NS = time.time_ns()
TOPICS = {channel.schema_name: channel.topic for channel in CHANNELS}  # a topic of each type


def payload_with(message: object, **changes: object) -> bytes:
    return json.dumps({**codec.to_dict(message), **changes}).encode()


def test_every_registered_type_has_an_example_here() -> None:
    assert set(TOPICS) == set(SCHEMA_TYPES)


@pytest.mark.parametrize("name", sorted(TOPICS))
def test_every_field_refuses_what_its_bounds_refuse_naming_it(name: str) -> None:
    message_type = SCHEMA_TYPES[name]
    message = template(TOPICS[name], "st1", NOW_NS)
    assert codec.decode(message_type, codec.encode(message)) == message
    decoders: list[Callable[[bytes], object]] = [lambda p: codec.decode(message_type, p)]
    if message_type not in (StickSlipEvent, ControllerResult, SampleBatch):
        decoders.append(codec.decoder(message_type))
    for field in codec.to_dict(message):
        for value in refused_values(message_type, field):
            payload = payload_with(message, **{field: value})
            for decode in decoders:
                with pytest.raises(InputError, match=f"not a valid {message_type.__name__}"):
                    decode(payload)


@pytest.mark.parametrize("name", sorted(TOPICS))
def test_every_field_takes_the_values_at_the_edges_of_its_bounds(name: str) -> None:
    """The fuzz sends these as valid (a service's own rules may still refuse them): a value
    the contract refuses among them makes a service's refusal look wrong."""
    message_type = SCHEMA_TYPES[name]
    message = template(TOPICS[name], "st1", NOW_NS)
    for field in (f.name for f in dataclasses.fields(message_type)):
        for value in extreme_values(message_type, field):
            payload = payload_with(message, **{field: value})
            try:
                codec.decode(message_type, payload)
            except InputError as err:
                raise AssertionError(f"{name}.{field} = {value!r} is refused: {err}") from err


@pytest.mark.parametrize(
    ("changes", "error"),
    [
        ({"time_ns": -1}, "time_ns is -1, expected 0 to 2**63 - 1"),
        ({"time_ns": 10**30}, "time_ns is 1000000000000000000000000000000, expected 0 to"),
        ({"time_ns": 1e30}, "time_ns is 1000000000000000019884624838656, expected"),
        ({"run_id": -1}, "run_id is -1, expected 0 to 2**63 - 1"),
        ({"sequence": 2**63}, "sequence is 9223372036854775808, expected 0 to 2**63 - 1"),
        ({"torque_nm": 10**400}, "torque_nm is an integer of 401 digits, beyond any number"),
        ({"station": "st 1"}, "station is 'st 1', expected [A-Za-z0-9_-]{1,64}"),
        ({"station": "s" * 65}, "station has 65 characters, expected at most 64"),
        ({"station": "st1\n"}, "station is 'st1\\n', expected"),
    ],
)
def test_a_sample_out_of_bounds_names_the_field_and_its_bounds(
    changes: dict[str, object], error: str
) -> None:
    payload = payload_with(template("samples", "st1", NOW_NS), **changes)
    with pytest.raises(InputError) as raised:
        codec.decoder(Sample)(payload)
    assert error in str(raised.value)
    assert len(str(raised.value)) < 200  # a refused value is quoted short


def test_figures_are_finite_and_measured_values_may_be_anything_a_bus_says() -> None:
    decision = template("decision", "st1", NOW_NS)
    for field in ("time_s", "force_n", "predicted_force_n"):
        with pytest.raises(InputError, match=f"{field} is nan, expected a finite number"):
            codec.decode(StopDecision, payload_with(decision, **{field: math.nan}))
    # an input_fault after non-finite samples quotes a NaN torque: still a decision
    assert math.isnan(
        codec.decode(StopDecision, payload_with(decision, torque_nm=math.nan)).torque_nm
    )
    sample = codec.decoder(Sample)(
        payload_with(template("samples", "st1", NOW_NS), torque_nm=-math.inf, angle_deg=1e308)
    )
    assert sample.torque_nm == -math.inf and sample.angle_deg == 1e308
    summary = template("runs", "st1", NOW_NS)
    with pytest.raises(InputError, match="process_intensity is inf, expected a finite number"):
        codec.decoder(RunSummary)(payload_with(summary, process_intensity=math.inf))


def test_texts_are_bounded() -> None:
    decision = template("decision", "st1", NOW_NS)
    at_limit = payload_with(decision, detail="d" * MAX_TEXT_CHARS)
    assert len(codec.decode(StopDecision, at_limit).detail) == MAX_TEXT_CHARS
    with pytest.raises(InputError, match=f"detail has {MAX_TEXT_CHARS + 1} characters"):
        codec.decode(StopDecision, payload_with(decision, detail="d" * (MAX_TEXT_CHARS + 1)))


@pytest.mark.parametrize("depth", [1_000, 12_000, 30_000, 100_000])
@pytest.mark.parametrize("opening", [b"[", b'{"a":'])
def test_deep_nesting_is_an_input_error_never_a_recursion_error(depth: int, opening: bytes) -> None:
    payload = opening * depth + b"1" + (b"]" if opening == b"[" else b"}") * depth
    if len(payload) > codec.MAX_PAYLOAD_BYTES:
        expected = "bytes, expected at most"
    elif depth > 10_000:  # past any recursion limit of the parser
        expected = "nested too deeply"
    else:
        expected = r"not a valid .* message: (nested too deeply|not a JSON object|unknown)"
    for decode in (codec.decoder(Sample), lambda p: codec.decode(StickSlipEvent, p)):
        with pytest.raises(InputError, match=expected):
            decode(payload)


def test_a_payload_beyond_the_size_bound_is_refused_unread() -> None:
    huge = json.dumps({"station": "s" * codec.MAX_PAYLOAD_BYTES}).encode()
    with pytest.raises(InputError, match=f"expected at most {codec.MAX_PAYLOAD_BYTES}"):
        codec.decoder(Sample)(huge)
    with pytest.raises(InputError, match=f"expected at most {codec.MAX_PAYLOAD_BYTES}"):
        codec.decode(ControllerResult, huge)


def test_nested_messages_are_checked_item_by_item() -> None:
    event = template("events", "st1", NOW_NS)
    fields = codec.to_dict(event)
    fields["predictions"][0]["time_s"] = math.nan
    with pytest.raises(InputError, match=r"predictions: .*time_s is nan"):
        codec.decode(StickSlipEvent, json.dumps(fields).encode())
    del fields["predictions"]  # a field with a default factory may be missing
    assert codec.decode(StickSlipEvent, json.dumps(fields).encode()).predictions == []


def test_a_narrower_decoder_takes_ids_only_as_wide_as_a_can_signal() -> None:
    state = template("tool", "st1", NOW_NS)
    narrow = codec.decoder(ToolState, {"run_id": (0, 2**32 - 1), "program_id": (0, 255)})
    assert narrow(payload_with(state, run_id=2**32 - 1)).run_id == 2**32 - 1
    with pytest.raises(InputError, match="run_id is 4294967296, expected 0 to 4294967295"):
        narrow(payload_with(state, run_id=2**32))
    with pytest.raises(InputError, match="program_id is 256, expected 0 to 255"):
        narrow(payload_with(state, program_id=256))
    assert codec.decoder(ToolState)(payload_with(state, run_id=2**40)).run_id == 2**40


@pytest.mark.parametrize("name", sorted(SCHEMA_TYPES))
def test_schemas_state_the_bounds_and_stay_what_foxglove_decodes(name: str) -> None:
    schema = codec.json_schema(SCHEMA_TYPES[name])
    jsonschema.Draft202012Validator.check_schema(schema)
    assert schema["type"] == "object"  # Foxglove needs an object at the root
    properties = schema["properties"]
    time_field = "ended_ns" if name == "boltwatch.RunSummary" else "time_ns"
    assert properties["station"]["pattern"] == "^[A-Za-z0-9_-]{1,64}$"
    assert properties[time_field]["minimum"] == 0
    assert properties[time_field]["maximum"] == 2**63 - 1
    message = template(TOPICS[name], "st1", NOW_NS)
    jsonschema.validate(json.loads(codec.encode(message)), schema)
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate({**json.loads(codec.encode(message)), time_field: -1}, schema)
