"""Message codecs, their JSON schemas, key expressions and the DBC enums agree."""

from __future__ import annotations

import json
import typing
from pathlib import Path
from typing import Any

import jsonschema
import pytest

from shared.contract import (
    CONTRACT,
    CYCLE_MESSAGES,
    SCHEMA_TYPES,
    STAGE_MESSAGES,
    BusStats,
    ControllerFunction,
    ControllerResult,
    ControllerStep,
    Prediction,
    RunSummary,
    Sample,
    StationDatabase,
    StickSlipEvent,
    StopDecision,
    StopReason,
    StopReasonName,
    ToolRunState,
    ToolState,
    channels,
    decode,
    encode,
    json_schema,
    keys,
)
from shared.errors import CanDatabaseError, InputError
from tests.support.paths import DBC_FILE

EXAMPLES = [
    Sample("st1", 4711, 12, 1_700_000_000_000_000_000, 187.5, 41.25, 55012.5),
    Sample("st1", 4711, 13, 1_700_000_000_001_000_000, 187.5, 41.25, None),
    ToolState("st1", 4711, 7, 1, "running", 1),
    BusStats("st1", 1, 10, 5, 0, 1, 0, 0, 0, 1, 3, 0, 2, 0, 1),
    StickSlipEvent(
        "st1",
        4711,
        3,
        5,
        0.25,
        190.0,
        150.0,
        40.0,
        52000.0,
        1300.0,
        0.02,
        50.0,
        12.5,
        3.1,
        9.9,
        1.2e5,
        3.4e5,
        [Prediction(1, 0.27, 192.0, 53300.0)],
    ),
    StopDecision("st1", 4711, 5, 0.3, "plateau_closest", "next 57.4 kN", 190.0, 55e3, 57e3, 6),
    StopDecision("st1", 4711, 5, 0.3, "target_reached", "", 1.4, None, 1.41, 5, advisory=True),
    ControllerResult(
        "cs351",
        1596334,
        955000040,
        0,
        9,
        "OK",
        "1",
        "30000000008730",
        "Nm",
        37,
        -1,
        -1,
        -1,
        -1,
        -1,
        -1,
        -1,
        None,
        [
            ControllerStep("Finding", "OK", "1", 96, [ControllerFunction("TF Angle", 100, 100.25)]),
            ControllerStep("Tightening 1.4", "NOK", "2", 73, []),
        ],
    ),
    RunSummary(
        "st1",
        4711,
        7,
        1,
        "done",
        56000.0,
        None,
        55500.0,
        190.0,
        -0.89,
        20,
        "plateau_closest",
        1e6,
        1500,
        1,
        2,
    ),
]


@pytest.mark.parametrize("message", EXAMPLES, ids=lambda m: type(m).__name__)
def test_round_trip_and_schema_validates_the_payload(message: Any) -> None:
    payload = encode(message)
    assert decode(type(message), payload) == message
    schema = json_schema(type(message))
    jsonschema.Draft202012Validator.check_schema(schema)
    jsonschema.validate(json.loads(payload), schema)


def test_every_message_type_has_a_registered_schema() -> None:
    for name, message_type in SCHEMA_TYPES.items():
        assert json_schema(message_type)["title"] == name


def test_decode_rejects_garbage_with_input_error() -> None:
    with pytest.raises(InputError, match="not a valid Sample"):
        decode(Sample, b"{not json")
    with pytest.raises(InputError):
        decode(Sample, b'{"station": "st1"}')


def test_dbc_enums_match_the_code() -> None:
    import cantools

    database = cantools.database.load_file(str(DBC_FILE))
    assert isinstance(database, cantools.database.can.Database)
    states = database.get_message_by_name("ToolStatus").get_signal_by_name("State").choices
    reasons = database.get_message_by_name("StopCommand").get_signal_by_name("Reason").choices
    assert states is not None and reasons is not None
    assert {int(k): str(v) for k, v in states.items()} == {
        s.value: s.name.lower() for s in ToolRunState
    }
    assert {int(k): str(v) for k, v in reasons.items()} == {
        r.value: r.name.lower() for r in StopReason
    }
    assert set(typing.get_args(StopReasonName)) == {r.name.lower() for r in StopReason}


def test_dbc_missing_a_contract_message_is_an_error(tmp_path: Path) -> None:
    text = DBC_FILE.read_text().replace("BO_ 257 JointSensors", "BO_ 257 JointSensorz")
    broken = tmp_path / "broken.dbc"
    broken.write_text(text)
    with pytest.raises(CanDatabaseError, match="JointSensors missing"):
        StationDatabase(broken)
    shipped = {name for name, _ in StationDatabase(DBC_FILE).by_id.values()}
    # it runs a final stage too, and can be a multi-spindle system
    assert shipped == set(CONTRACT) | set(STAGE_MESSAGES) | set(CYCLE_MESSAGES)


def test_keys() -> None:
    assert channels.SAMPLES.key("st1") == "boltwatch/st1/samples"
    assert keys.split_key("boltwatch/st1/health/predictor") == ("st1", "health/predictor")
    with pytest.raises(ValueError, match="not a boltwatch station key"):
        keys.split_key("other/st1/samples")


def test_a_live_decision_without_advisory_still_decodes_and_validates() -> None:
    """``advisory`` came later with a default: older payloads stay valid, and mean live."""
    from shared.recordings import classify  # what the recorder files it as

    old = {
        "station": "st1",
        "run_id": 7,
        "time_ns": 5,
        "time_s": 0.3,
        "reason": "plateau_closest",
        "detail": "",
        "torque_nm": 190.0,
        "force_n": 5.5e4,
        "predicted_force_n": 5.7e4,
        "decided_ns": 6,
    }
    payload = json.dumps(old).encode()
    jsonschema.validate(old, json_schema(StopDecision))
    assert decode(StopDecision, payload).advisory is False
    received = classify("boltwatch/st1/decision", payload, 10)
    assert received.message is not None and received.message.advisory is False
    assert "advisory" not in json_schema(StopDecision)["required"]
