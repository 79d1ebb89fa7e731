"""Conformance: the codec against other implementations' and the specification's example messages.

The examples are data (``tests/data/openprotocol/examples/*.toml``, one file per
source), each naming where it comes from. For every example:

- it frames, whole and fed one byte at a time;
- it decodes, and the values the source states come out (``expect``);
- unless ``roundtrip = false`` (the entry says why: a header or padding variant
  that ``encode`` does not write), ``encode`` gives the same bytes back;
- a 0900 subscription (0008) asks the trace types the source states
  (``trace_types``);
- an example of a revision the codec does not implement is refused naming the
  revision (``refused = "revision"``), and one with content the codec refuses
  (``refused = "<field>"``) names that field: both are listed, not hidden.

An entry gives either ``wire`` (the whole message as the source writes it,
``\\u0000`` for NUL; ``tail_hex``, if present, is appended as bytes: 0900's
binary samples) or ``data`` (the source gives the data field only: the test
puts our default header in front and a NUL after it).
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from typing import Any

import pytest

from shared.openprotocol import (
    KNOWN_MIDS,
    DataSubscribe,
    Dialect,
    Frame,
    FrameReader,
    OpenProtocolError,
    UnknownMessage,
    decode,
    encode,
    frame_bytes,
    trace_types_of,
)
from tests.support.paths import REPO

EXAMPLES_DIR = REPO / "tests" / "data" / "openprotocol" / "examples"
SENDERS = {"controller", "integrator"}
ENTRY_KEYS = {
    "id", "source", "mid", "revision", "sender", "wire", "tail_hex", "data", "expect",
    "refused", "roundtrip", "variant", "header_fill", "trace_byte_order", "trace_types", "note",
}  # fmt: skip


@dataclass(frozen=True)
class Example:
    id: str
    source: str
    mid: int
    revision: int
    sender: str
    wire: bytes
    dialect: Dialect
    expect: dict[str, Any] = field(default_factory=dict)
    refused: str | None = None
    roundtrip: bool = True
    trace_types: tuple[int, ...] | None = None


def _example(entry: dict[str, Any], file: str) -> Example:
    unknown = set(entry) - ENTRY_KEYS
    assert not unknown, f"{file} {entry.get('id')}: unknown keys {unknown}"
    assert ("wire" in entry) != ("data" in entry), f"{file} {entry['id']}: wire or data"
    tail = bytes.fromhex(entry.get("tail_hex", ""))
    if "data" in entry:
        data = entry["data"].encode("latin-1") + tail
        wire = frame_bytes(Frame(mid=entry["mid"], revision=entry["revision"], data=data))
    else:
        wire = entry["wire"].encode("latin-1") + tail
    assert entry["sender"] in SENDERS, f"{file} {entry['id']}: sender"
    assert entry.get("roundtrip", True) or entry.get("variant"), f"{entry['id']}: say why"
    dialect = Dialect(
        header_fill=entry.get("header_fill", "space"),
        nul_terminator=len(wire) > int(wire[:4]),
        trace_byte_order=entry.get("trace_byte_order", "big"),
        trace_nul_separator=True,
    )
    return Example(
        id=entry["id"],
        source=f"{file}: {entry['source']}",
        mid=entry["mid"],
        revision=entry["revision"],
        sender=entry["sender"],
        wire=wire,
        dialect=dialect,
        expect=entry.get("expect", {}),
        refused=entry.get("refused"),
        roundtrip=entry.get("roundtrip", True) and "refused" not in entry,
        trace_types=tuple(entry["trace_types"]) if "trace_types" in entry else None,
    )


def _load() -> list[Example]:
    examples = []
    for path in sorted(EXAMPLES_DIR.glob("*.toml")):
        document = tomllib.loads(path.read_text(encoding="utf-8"))
        examples += [_example(entry, path.name) for entry in document["example"]]
    return examples


EXAMPLES = _load()
DECODED = [e for e in EXAMPLES if e.refused is None]
ROUND_TRIPS = [e for e in DECODED if e.roundtrip]
TRACE_SUBSCRIPTIONS = [e for e in DECODED if e.trace_types is not None]
REFUSED_REVISIONS = [e for e in EXAMPLES if e.refused == "revision"]
REFUSED_CONTENT = [e for e in EXAMPLES if e.refused not in (None, "revision")]


def _ids(examples: list[Example]) -> list[str]:
    return [e.id for e in examples]


def _frame(example: Example) -> Frame:
    reader = FrameReader(known_mids=KNOWN_MIDS)
    frames = reader.feed(example.wire)
    assert len(frames) == 1, example.source
    assert (reader.garbage_bytes, reader.bad_frames, reader.pending_bytes) == (0, 0, 0)
    return frames[0]


def test_the_examples_are_many_unique_and_say_where_they_come_from() -> None:
    assert len({e.id for e in EXAMPLES}) == len(EXAMPLES) > 100
    assert all(e.source.count(" ") >= 2 for e in EXAMPLES)


@pytest.mark.parametrize("example", EXAMPLES, ids=_ids(EXAMPLES))
def test_frames_whole_and_byte_by_byte(example: Example) -> None:
    frame = _frame(example)
    assert (frame.mid, frame.revision) == (example.mid, example.revision), example.source
    reader = FrameReader(known_mids=KNOWN_MIDS)
    one_by_one = [f for i in range(len(example.wire)) for f in reader.feed(example.wire[i : i + 1])]
    assert one_by_one == [frame]
    assert (reader.garbage_bytes, reader.bad_frames, reader.pending_bytes) == (0, 0, 0)


def _same(actual: object, expected: object) -> bool:
    if isinstance(expected, bool) or isinstance(actual, bool):
        return actual is expected
    if isinstance(expected, float):
        return isinstance(actual, float) and math.isclose(actual, expected, abs_tol=1e-9)
    if isinstance(expected, dict):  # a record in a message (a spindle of 0091, 0101)
        return all(_same(getattr(actual, name), value) for name, value in expected.items())
    if isinstance(expected, list):
        return (
            isinstance(actual, tuple)
            and len(actual) == len(expected)
            and all(map(_same, actual, expected))
        )
    return type(actual) is not float and actual == expected


@pytest.mark.parametrize("example", DECODED, ids=_ids(DECODED))
def test_decodes_to_the_values_the_source_states(example: Example) -> None:
    message = decode(_frame(example), dialect=example.dialect)
    assert not isinstance(message, UnknownMessage)
    assert (message.MID, message.revision) == (example.mid, example.revision)
    for name, expected in example.expect.items():
        actual = getattr(message, name)
        assert _same(actual, expected), f"{name}: {actual!r} != {expected!r} ({example.source})"


@pytest.mark.parametrize("example", ROUND_TRIPS, ids=_ids(ROUND_TRIPS))
def test_encodes_back_to_the_same_bytes(example: Example) -> None:
    frame = _frame(example)
    message = decode(frame, dialect=example.dialect)
    assert not isinstance(message, UnknownMessage)
    wire = encode(message, revision=frame.revision, dialect=example.dialect, no_ack=frame.no_ack)
    assert wire == example.wire, example.source


@pytest.mark.parametrize("example", TRACE_SUBSCRIPTIONS, ids=_ids(TRACE_SUBSCRIPTIONS))
def test_a_0900_subscription_asks_the_trace_types_the_source_states(example: Example) -> None:
    message = decode(_frame(example), dialect=example.dialect)
    assert isinstance(message, DataSubscribe)
    assert trace_types_of(message.extra_data) == example.trace_types, example.source


@pytest.mark.parametrize("example", REFUSED_REVISIONS, ids=_ids(REFUSED_REVISIONS))
def test_refuses_a_revision_not_implemented(example: Example) -> None:
    with pytest.raises(OpenProtocolError) as refused:
        decode(_frame(example), dialect=example.dialect)
    assert (refused.value.field, refused.value.revision) == ("revision", example.revision)


@pytest.mark.parametrize("example", REFUSED_CONTENT, ids=_ids(REFUSED_CONTENT))
def test_refuses_content_out_of_the_specification(example: Example) -> None:
    with pytest.raises(OpenProtocolError) as refused:
        decode(_frame(example), dialect=example.dialect)
    assert refused.value.field == example.refused, example.source
