"""The part at a station (``boltwatch/<st>/part``): its message, its bounds and its channel."""

from __future__ import annotations

import json
from dataclasses import replace

import jsonschema
import pytest

from shared.contract import (
    PART_ID_CHARS,
    PartScan,
    TighteningResult,
    channels,
    decode,
    decoder,
    encode,
    json_schema,
    to_dict,
)
from shared.errors import InputError
from tests.support import factories

T_NS = 1_700_000_000_000_000_000


def payload(**changes: object) -> bytes:
    fields: dict[str, object] = {"station": "st1", "part_id": "WVWZZZ1JZXW000001", "time_ns": T_NS}
    return json.dumps({**fields, **changes}).encode()


@pytest.mark.parametrize(
    "part_id",
    [
        "WVWZZZ1JZXW000001",  # a VIN
        "st1-P1718000000",  # the simulated line's
        "HEAD 4711/B",  # a space inside, a slash: a data matrix code's text
        "x",
        "~" * PART_ID_CHARS,
    ],
)
def test_a_part_scan_round_trips_and_its_schema_takes_it(part_id: str) -> None:
    scan = PartScan("st1", part_id, T_NS)
    encoded = encode(scan)
    assert decode(PartScan, encoded) == scan
    assert decoder(PartScan)(encoded) == scan
    schema = json_schema(PartScan)
    jsonschema.Draft202012Validator.check_schema(schema)
    jsonschema.validate(json.loads(encoded), schema)
    assert schema["title"] == "boltwatch.PartScan"


@pytest.mark.parametrize(
    ("changes", "error"),
    [
        ({"part_id": ""}, "part_id is '', expected"),
        ({"part_id": " WVW1"}, "part_id is ' WVW1', expected"),  # a scanner's padding
        ({"part_id": "WVW1 "}, "part_id is 'WVW1 ', expected"),
        ({"part_id": "A\x1dB"}, "part_id is 'A\\x1dB', expected"),  # a GS1 separator
        ({"part_id": "A\tB"}, "part_id is 'A\\tB', expected"),
        ({"part_id": "Teil-Ü1"}, "part_id is 'Teil-Ü1', expected"),
        ({"part_id": "x" * (PART_ID_CHARS + 1)}, "part_id has 101 characters, expected at most"),
        ({"part_id": None}, "part_id"),
        ({"part_id": 4711}, "part_id"),
        ({"station": "st 1"}, "station is 'st 1'"),
        ({"time_ns": -1}, "time_ns is -1"),
        ({"bolts": 4}, "bolts"),  # no field of the message
    ],
)
def test_a_bad_part_scan_is_refused_naming_the_field(
    changes: dict[str, object], error: str
) -> None:
    for decode_it in (decoder(PartScan), lambda p: decode(PartScan, p)):
        with pytest.raises(InputError, match="not a valid PartScan") as raised:
            decode_it(payload(**changes))
        assert error in str(raised.value)
    schema = json_schema(PartScan)
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(json.loads(payload(**changes)), schema)


def test_a_part_scan_without_its_part_is_refused() -> None:
    document = json.loads(payload())
    del document["part_id"]
    with pytest.raises(InputError, match="part_id"):
        decode(PartScan, json.dumps(document).encode())


def test_the_part_channel_is_put_by_the_lines_plc_or_the_rig_express() -> None:
    channel = channels.by_topic("part")
    assert channel is channels.PART
    assert channel.message_type is PartScan and channel.schema_name == "boltwatch.PartScan"
    assert channel.key("st1") == "boltwatch/st1/part"
    assert channel.publishers == ("plc", "rig")
    assert channel.qos.express and not channel.qos.real_time
    assert channels.of_message(PartScan("st1", "P1", T_NS)) is channel
    assert channels.topics_of("rig") == ("part",) == channels.topics_of("plc")


def test_a_result_recorded_before_it_said_where_its_part_came_from_still_decodes() -> None:
    """``TighteningResult.part_source`` is optional: a result in a recording (or from a
    station) made before it decodes, saying nothing of its part's source; one that says it
    must say one of the three."""
    result = factories.result(1, part_id="WHEEL-A", part_source="restored")
    older = to_dict(result)
    del older["part_source"]
    decoded = decode(TighteningResult, json.dumps(older).encode())
    assert decoded == replace(result, part_source=None)
    assert decode(TighteningResult, encode(result)) == result
    with pytest.raises(InputError, match="part_source"):
        decode(TighteningResult, json.dumps({**older, "part_source": "guessed"}).encode())
