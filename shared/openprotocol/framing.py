"""Open Protocol framing: the 20-byte header, the wire bytes, a stream reader.

A message on the wire (Atlas Copco Open Protocol, TCP port 4545)::

    offset  width  field
    0       4      length: header + data, WITHOUT the trailing NUL (ASCII digits)
    4       4      MID (ASCII digits)
    8       3      revision: "000", "001" or three spaces all mean 1
    11      1      no-ack flag: "1" = no acknowledge wanted; " " or "0" = acknowledge
    12      2      station id      } two spaces or "00": not used (None)
    14      2      spindle id      }
    16      2      sequence number }
    18      1      number of message parts } a space or "0": not used (None)
    19      1      message part number     }
    20      n      data (ASCII; 0900 carries binary samples after its ASCII part)
    20+n    1      NUL (0x00) terminator -- some controllers omit it

Writing: the revision is always three digits ("001"); a field that is None
is written as spaces (``fill="space"``, the default) or zeros
(``fill="zero"``), a per-controller setting. The default follows the
specification's "space or zero: not used" wording and OpenProtocolInterpreter's
header writer, which both write spaces.

:class:`FrameReader` accepts exactly:

- a header whose length field is 4 digits in [20, ``max_length``], MID 4
  digits (not 0000), revision 3 digits or spaces, no-ack " "/"0"/"1", the
  station/spindle/sequence fields 2 digits or spaces, the part fields a digit
  or space; then ``length - 20`` data bytes; then one optional NUL;
- any split of that stream into chunks (a read may end inside a header,
  inside the data, or inside the next message; one read may hold several).

Resynchronising after garbage, a header is believed only when, besides the
shape above, its MID is one of ``known_mids`` (when given: the codec passes
:data:`shared.openprotocol.codec.KNOWN_MIDS`), and, for an ASCII-only MID,
its data up to its length holds no NUL (else its length reaches into the next
message). Bytes are then dropped one at a time until a header is believed.

It never raises. What it must drop it counts: ``garbage_bytes`` (every byte
dropped while looking for the next plausible header, including the bytes of
a bad frame), ``bad_frames`` (where a message was due, right after a message
or at the start: the header's MID, revision and flags look right but its
length field is not digits, < 20 or > ``max_length``; or its data holds a NUL
where only ASCII may be, i.e. its length reaches into the next message).

Limits: a wrong length that stays plausible and reaches no NUL (a controller
that sends no terminators) is not detectable here: the message decoder
refuses its content and the reader resynchronises after it. Multi-part
(linked) messages are returned part by part; nothing here joins them.
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass
from typing import Final, Literal

from shared.openprotocol.errors import OpenProtocolError

HeaderFill = Literal["space", "zero"]

HEADER_BYTES: Final = 20
MAX_LENGTH: Final = 9999  # 4 digits: the specification's largest message (longer ones are linked)
DEFAULT_HEADER_FILL: Final[HeaderFill] = "space"
NUL: Final = 0x00
BINARY_MIDS: Final = frozenset({900, 901})  # data holds binary after an ASCII part

_DIGITS: Final = frozenset(b"0123456789")
_DIGIT_OR_SPACE: Final = _DIGITS | {ord(" ")}
_NO_ACK: Final = frozenset(b" 01")


@dataclass(frozen=True, slots=True)
class Frame:
    """One message: its header fields and its data (no header, no NUL terminator)."""

    mid: int
    revision: int = 1
    no_ack: bool = False
    station_id: int | None = None
    spindle_id: int | None = None
    sequence: int | None = None
    parts: int | None = None
    part_number: int | None = None
    data: bytes = b""


def frame_bytes(
    frame: Frame | int,
    data: bytes = b"",
    *,
    revision: int = 1,
    fill: HeaderFill = DEFAULT_HEADER_FILL,
    terminator: bool = True,
) -> bytes:
    """The wire bytes of ``frame`` (or of MID ``frame`` with ``data`` at ``revision``).

    ``terminator``: append the NUL (the specification's form; some
    controllers omit it). Raises :class:`OpenProtocolError` for a header
    value that does not fit its field or a message longer than 9999 bytes.
    """
    if isinstance(frame, int):
        frame = Frame(mid=frame, revision=revision, data=data)
    length = HEADER_BYTES + len(frame.data)
    if length > MAX_LENGTH:
        why = f"{length} bytes do not fit 4 digits (at most {MAX_LENGTH})"
        raise OpenProtocolError(frame.mid, "length", why)
    blank = " " if fill == "space" else "0"
    header = (
        f"{length:04d}"
        + _digits(frame.mid, frame.mid, "mid", 4, None, lowest=1)
        + _digits(frame.mid, frame.revision, "revision", 3, None, lowest=1)
        + ("1" if frame.no_ack else blank)
        + _digits(frame.mid, frame.station_id, "station id", 2, blank)
        + _digits(frame.mid, frame.spindle_id, "spindle id", 2, blank)
        + _digits(frame.mid, frame.sequence, "sequence number", 2, blank)
        + _digits(frame.mid, frame.parts, "number of message parts", 1, blank)
        + _digits(frame.mid, frame.part_number, "message part number", 1, blank)
    )
    return header.encode("ascii") + frame.data + (b"\x00" if terminator else b"")


def _digits(
    mid: int, value: int | None, field: str, width: int, blank: str | None, *, lowest: int = 0
) -> str:
    if value is None:
        if blank is None:
            raise OpenProtocolError(mid, field, "is needed")
        return blank * width
    if not lowest <= value < 10**width:
        raise OpenProtocolError(mid, field, f"{value} is not in [{lowest}, {10**width - 1}]")
    return f"{value:0{width}d}"


def _plausible_tail(head: bytes) -> bool:
    """Bytes 4..19 of ``head`` look like a header's MID, revision and flags."""
    return (
        all(b in _DIGITS for b in head[4:8])
        and head[4:8] != b"0000"
        and all(b in _DIGIT_OR_SPACE for b in head[8:11])
        and head[11] in _NO_ACK
        and all(b in _DIGIT_OR_SPACE for b in head[12:20])
    )


def _length_of(head: bytes, max_length: int) -> int | None:
    """The length field when it is 4 digits in [20, max_length], else None."""
    if not all(b in _DIGITS for b in head[:4]):
        return None
    length = int(head[:4])
    return length if HEADER_BYTES <= length <= max_length else None


def _could_start_header(prefix: bytes) -> bool:
    """``prefix`` (shorter than a header) may still grow into a plausible header."""
    shape = (_DIGITS,) * 8 + (_DIGIT_OR_SPACE,) * 3 + (_NO_ACK,) + (_DIGIT_OR_SPACE,) * 8
    return all(b in allowed for b, allowed in zip(prefix, shape, strict=False))


def _optional(text: bytes) -> int | None:
    """A header number that may be blank: spaces or zeros mean "not used"."""
    stripped = text.strip(b" ")
    if not stripped or int(stripped) == 0:
        return None
    return int(stripped)


def parse_header(head: bytes, data: bytes | bytearray) -> Frame:
    """The frame of a plausible 20-byte header ``head`` and its ``data``."""
    revision_text = head[8:11].strip(b" ")
    return Frame(
        mid=int(head[4:8]),
        revision=max(int(revision_text), 1) if revision_text else 1,
        no_ack=head[11:12] == b"1",
        station_id=_optional(head[12:14]),
        spindle_id=_optional(head[14:16]),
        sequence=_optional(head[16:18]),
        parts=_optional(head[18:19]),
        part_number=_optional(head[19:20]),
        data=bytes(data),
    )


class FrameReader:
    """Frames out of a TCP byte stream, whatever the reads' boundaries (see the module doc)."""

    def __init__(
        self, *, max_length: int = MAX_LENGTH, known_mids: Collection[int] | None = None
    ) -> None:
        if not HEADER_BYTES <= max_length <= MAX_LENGTH:
            raise ValueError(f"max_length {max_length} is not in [20, {MAX_LENGTH}]")
        self.max_length = max_length
        self.known_mids = None if known_mids is None else frozenset(known_mids)
        self.garbage_bytes = 0
        self.bad_frames = 0
        self.frames = 0
        self._buffer = bytearray()
        self._in_sync = True  # at the start or right after a message: a message is due here
        self._after_message = False  # a NUL terminator may come next

    @property
    def pending_bytes(self) -> int:
        """Bytes held for a message not yet complete (a truncated tail at the end of a stream)."""
        return len(self._buffer)

    def feed(self, chunk: bytes) -> list[Frame]:
        """The messages that ``chunk`` completes, in order; keeps any partial one for later."""
        self._buffer += chunk
        frames: list[Frame] = []
        buffer = self._buffer
        while buffer:
            if self._after_message:
                self._after_message = False
                if buffer[0] == NUL:
                    del buffer[0]
                    continue
            if len(buffer) < HEADER_BYTES:
                if _could_start_header(bytes(buffer)):
                    break
                self._drop(1)
                continue
            head = bytes(buffer[:HEADER_BYTES])
            length = _length_of(head, self.max_length)
            if length is None or not _plausible_tail(head):
                if self._in_sync and _plausible_tail(head):
                    self.bad_frames += 1
                self._drop(1)
                continue
            mid = int(head[4:8])
            if not self._in_sync and self.known_mids is not None and mid not in self.known_mids:
                self._drop(1)
                continue
            available = buffer[HEADER_BYTES : min(length, len(buffer))]
            if mid not in BINARY_MIDS and NUL in available:
                if self._in_sync:  # its length reaches past a NUL: into the next message
                    self.bad_frames += 1
                self._drop(1)
                continue
            if len(buffer) < length:
                break
            frames.append(parse_header(head, buffer[HEADER_BYTES:length]))
            del buffer[:length]
            self.frames += 1
            self._in_sync = True
            self._after_message = True
        return frames

    def _drop(self, count: int) -> None:
        del self._buffer[:count]
        self.garbage_bytes += count
        self._in_sync = False
