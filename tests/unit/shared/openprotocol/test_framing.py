"""Open Protocol framing: header bytes both fills, and FrameReader over any split of a stream."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from shared.openprotocol import Frame, FrameReader, OpenProtocolError, frame_bytes

# Written by hand from the header layout: 0001 rev 1, no data.
START_SPACES = b"00200001001         \x00"
START_ZEROS = b"00200001001000000000\x00"
KEEP_ALIVE = b"00209999001         \x00"
RESULT_ACK = b"00200062001         \x00"
ERROR_97 = b"00260004001         006097\x00"  # 0004: MID 0060 refused, error 97


def test_frame_bytes_fills_unused_header_fields_with_spaces_or_zeros() -> None:
    assert frame_bytes(1) == START_SPACES
    assert frame_bytes(1, fill="zero") == START_ZEROS
    assert frame_bytes(Frame(mid=4, data=b"006097")) == ERROR_97
    assert frame_bytes(9999, terminator=False) == KEEP_ALIVE[:-1]


def test_frame_bytes_writes_every_header_field() -> None:
    frame = Frame(
        mid=61,
        revision=2,
        no_ack=True,
        station_id=1,
        spindle_id=2,
        sequence=3,
        parts=1,
        part_number=1,
        data=b"x",
    )
    assert frame_bytes(frame) == b"00210061002101020311x\x00"
    assert FrameReader().feed(frame_bytes(frame)) == [frame]


@pytest.mark.parametrize(
    ("header", "revision"),
    [
        (b"00200001000         ", 1),
        (b"00200001            ", 1),
        (b"00200001001         ", 1),
        (b"00200001003         ", 3),
        (b"00200001  3         ", 3),
    ],
)
def test_revision_000_spaces_and_001_all_mean_1(header: bytes, revision: int) -> None:
    assert FrameReader().feed(header) == [Frame(mid=1, revision=revision)]


def test_zeros_and_spaces_in_the_header_read_the_same() -> None:
    assert FrameReader().feed(START_ZEROS) == FrameReader().feed(START_SPACES) == [Frame(mid=1)]


def test_frame_bytes_refuses_values_that_do_not_fit() -> None:
    with pytest.raises(OpenProtocolError) as refused:
        frame_bytes(Frame(mid=61, station_id=100))
    assert str(refused.value) == "MID 0061, field 'station id': 100 is not in [0, 99]"
    with pytest.raises(OpenProtocolError) as refused:
        frame_bytes(900, b"x" * 9980)
    assert str(refused.value) == (
        "MID 0900, field 'length': 10000 bytes do not fit 4 digits (at most 9999)"
    )
    with pytest.raises(OpenProtocolError) as refused:
        frame_bytes(1, revision=0)
    assert str(refused.value) == "MID 0001, field 'revision': 0 is not in [1, 999]"


STREAM_FRAMES = [
    Frame(mid=1, revision=3),
    Frame(mid=4, data=b"006097"),
    Frame(mid=9999),
    Frame(mid=900, data=b"0000000042ascii\x00\x01\x02\x00\xff"),  # binary with NULs inside
    Frame(mid=62, station_id=1),
]


def _stream(terminator: bool) -> bytes:
    return b"".join(frame_bytes(frame, terminator=terminator) for frame in STREAM_FRAMES)


def _read_in_chunks(stream: bytes, size: int, reader: FrameReader) -> list[Frame]:
    frames: list[Frame] = []
    for start in range(0, len(stream), size):
        frames += reader.feed(stream[start : start + size])
    return frames


@pytest.mark.parametrize("terminator", [True, False])
def test_every_chunk_size_gives_the_same_frames(terminator: bool) -> None:
    stream = _stream(terminator)
    for size in range(1, len(stream) + 1):
        reader = FrameReader()
        assert _read_in_chunks(stream, size, reader) == STREAM_FRAMES, size
        assert (reader.garbage_bytes, reader.bad_frames, reader.pending_bytes) == (0, 0, 0)


@given(cuts=st.lists(st.integers(min_value=0, max_value=200), max_size=12), nul=st.booleans())
def test_any_split_gives_the_same_frames(cuts: list[int], nul: bool) -> None:
    stream = _stream(nul)
    reader = FrameReader()
    frames: list[Frame] = []
    start = 0
    for cut in sorted(min(cut, len(stream)) for cut in cuts):
        frames += reader.feed(stream[start:cut])
        start = cut
    frames += reader.feed(stream[start:])
    assert frames == STREAM_FRAMES
    assert reader.garbage_bytes == reader.bad_frames == 0


GARBLED = b"\xff\xfeHELLO" + START_SPACES + b"zz\r\n" + KEEP_ALIVE + b"12" + RESULT_ACK


@pytest.mark.parametrize("known_mids", [None, {1, 9999, 62}])
@pytest.mark.parametrize("size", [1, 3, len(GARBLED)])
def test_garbage_before_and_between_messages_is_skipped_and_counted(
    known_mids: set[int] | None, size: int
) -> None:
    reader = FrameReader(known_mids=known_mids)
    frames = _read_in_chunks(GARBLED, size, reader)
    assert frames == [Frame(mid=1), Frame(mid=9999), Frame(mid=62)]
    assert reader.garbage_bytes == 7 + 4 + 2
    # "12" right after a message, where a message was due: "1200..." looks like
    # a header whose length reaches past the next NUL: one bad frame.
    assert reader.bad_frames == 1


def test_digits_before_a_header_without_terminators_need_the_known_mids() -> None:
    # After garbage, "12" + "0020 0062..." reads as a 1200-byte message of MID
    # 2000: only the known MIDs tell it apart when no NUL ends the messages.
    stream = b"\xff12" + frame_bytes(62, terminator=False) + frame_bytes(9999, terminator=False)
    assert FrameReader(known_mids={62, 9999}).feed(stream) == [Frame(mid=62), Frame(mid=9999)]
    assert FrameReader().feed(stream) == []


def test_a_length_that_is_not_digits_is_a_bad_frame_and_the_next_message_is_read() -> None:
    reader = FrameReader()
    stream = b"00x00061001         " + b"\x00" + KEEP_ALIVE
    assert reader.feed(stream) == [Frame(mid=9999)]
    assert reader.bad_frames == 1
    assert reader.garbage_bytes == 21


@pytest.mark.parametrize("length", [b"0019", b"9000"])
def test_a_length_below_20_or_above_the_maximum_is_a_bad_frame(length: bytes) -> None:
    reader = FrameReader(max_length=4000)
    assert reader.feed(length + b"0061001         \x00" + KEEP_ALIVE) == [Frame(mid=9999)]
    assert (reader.bad_frames, reader.garbage_bytes) == (1, 21)


def test_a_length_reaching_into_the_next_message_is_cut_at_the_nul() -> None:
    reader = FrameReader()
    too_long = b"00400005001         0060\x00"  # says 40 bytes, holds 24 then its NUL
    assert reader.feed(too_long + KEEP_ALIVE) == [Frame(mid=9999)]
    assert (reader.bad_frames, reader.garbage_bytes) == (1, 25)


def test_a_truncated_tail_is_held_not_returned() -> None:
    reader = FrameReader()
    assert reader.feed(START_SPACES + ERROR_97[:-5]) == [Frame(mid=1)]
    assert reader.pending_bytes == len(ERROR_97) - 5
    assert reader.feed(ERROR_97[-5:]) == [Frame(mid=4, data=b"006097")]
    assert reader.pending_bytes == 0


def test_a_short_length_leaves_the_rest_as_garbage_until_the_next_header() -> None:
    reader = FrameReader()
    short = b"00220004001         006097\x00"  # says 22: 2 data bytes, 4 left over
    frames = reader.feed(short + KEEP_ALIVE)
    assert frames == [Frame(mid=4, data=b"00"), Frame(mid=9999)]
    assert (reader.bad_frames, reader.garbage_bytes) == (0, 5)
