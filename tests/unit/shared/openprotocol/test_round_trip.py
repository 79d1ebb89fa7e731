"""Every message of every implemented revision survives encode -> FrameReader -> decode."""

from __future__ import annotations

import pytest

from shared.openprotocol import (
    ANY_REVISION_MIDS,
    BINARY_MIDS,
    KNOWN_MIDS,
    SUPPORTED_REVISIONS,
    CommandAccepted,
    CommandError,
    Dialect,
    Frame,
    FrameReader,
    OpenProtocolError,
    ResultSubscribe,
    UnknownMessage,
    WireMessage,
    decode,
    encode,
)
from tests.support.openprotocol_examples import EXAMPLES

DIALECTS = [
    Dialect(),
    Dialect(header_fill="zero", nul_terminator=False),
    Dialect(trace_byte_order="little", trace_nul_separator=False),
]


def test_the_examples_cover_every_mid_and_revision() -> None:
    covered: dict[int, set[int]] = {}
    for message in EXAMPLES:
        covered.setdefault(message.MID, set()).add(message.revision)
    assert covered == {mid: set(revisions) for mid, revisions in SUPPORTED_REVISIONS.items()}


@pytest.mark.parametrize("dialect", DIALECTS, ids=repr)
@pytest.mark.parametrize(
    "message", EXAMPLES, ids=lambda m: f"{m.MID:04d}-rev{m.revision}-{type(m).__name__}"
)
def test_round_trip(message: WireMessage, dialect: Dialect) -> None:
    wire = encode(message, dialect=dialect)
    reader = FrameReader(known_mids=KNOWN_MIDS)
    (frame,) = reader.feed(wire + wire)[:1]
    assert (frame.mid, frame.revision) == (message.MID, message.revision)
    assert decode(frame, dialect=dialect) == message
    ends_with_nul = dialect.nul_terminator and message.MID not in BINARY_MIDS  # spec 2.2.4
    assert wire[int(wire[:4]) :] == (b"\x00" if ends_with_nul else b"")


def test_an_unknown_mid_is_a_value_and_is_written_back_whole() -> None:
    frame = Frame(mid=215, revision=2, data=b"0101")
    message = decode(frame)
    assert message == UnknownMessage(frame)
    assert encode(message) == b"00240215002         0101\x00"


def test_a_revision_not_implemented_is_refused_naming_it() -> None:
    with pytest.raises(OpenProtocolError) as refused:
        decode(Frame(mid=1, revision=4))
    assert (
        str(refused.value)
        == "MID 0001 rev 4, field 'revision': revision 4 is not implemented (1, 2, 3)"
    )
    assert refused.value.field == "revision"
    with pytest.raises(OpenProtocolError) as refused:
        encode(ResultSubscribe(), revision=3)
    assert (
        str(refused.value)
        == "MID 0060 rev 3, field 'revision': revision 3 is not implemented (1, 2)"
    )


@pytest.mark.parametrize("mid", sorted(ANY_REVISION_MIDS))
def test_a_message_without_data_is_read_and_written_at_any_revision(mid: int) -> None:
    """0062, 0063, 0072, 0073, 0075, 0077, 0092, 0093, 0102, 0103, 0003 and 9999 carry no data
    at any revision (and OpenProtocolInterpreter writes 0062 at revision 5 or 6). Before:
    refused above 1."""
    assert {3, 62, 63, 72, 73, 75, 77, 92, 93, 102, 103, 9999} == ANY_REVISION_MIDS
    for revision in (2, 6, 999):
        message = decode(Frame(mid=mid, revision=revision))
        assert not isinstance(message, UnknownMessage)
        assert message.revision == revision
        assert encode(message)[:11] == f"0020{mid:04d}{revision:03d}".encode()


def test_encode_takes_a_revision_fill_and_no_ack() -> None:
    assert encode(CommandError(mid=60, error_code=97), revision=2, fill="zero", no_ack=True) == (
        b"00270004002100000000" b"0060097\x00"
    )  # fmt: skip


def test_a_pushed_trace_is_acknowledged_with_0005_naming_0900() -> None:
    assert encode(CommandAccepted(mid=900)) == b"00240005001         0900\x00"
