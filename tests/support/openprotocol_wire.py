"""Open Protocol framing and field formatting, written from the specification's text.

Source: Open Protocol Specification R2.8.0 (Atlas Copco 9836 4415 01), kept unchanged in
R2.16.0:

- 2.2.2 Header, Table 1: length (4 ASCII digits, header plus data field, the NUL not
  counted), MID (4 digits), revision (3 digits; three spaces, 000 and 001 all mean 1),
  no ack flag (1), station id (2), spindle id (2), sequence number (2), number of message
  parts (1), message part number (1); spaces where unused. Length and MID are padded left
  with '0'.
- 2.3 Static data field use, Table 3: a two-digit parameter id before each value; digits
  padded left with '0', text padded right with spaces.
- 2.4 Variable data field use, Table 4: PID (5), length (3), data type (2), unit (3), step
  number (4), value.
- 2.4.1 Message end: an ASCII message ends with NUL, not counted in the length.
- 2.2.4 A message with a binary part: the ASCII part ends with NUL, the binary part follows,
  "no NUL character is sent after the binary data", and the header length is the TOTAL
  length (header, ASCII part, that NUL and the binary part).
- 5.28.1 MID 9999 and 3.1: the controller's own timing rules are in the controller module.

Time stamps are 19 characters, YYYY-MM-DD:HH:MM:SS, local time (MID 0061 parameter 20).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

HEADER_SIZE = 20
NUL = b"\x00"


def digits(value: int, width: int) -> str:
    """An unsigned number padded left with '0' to exactly `width` digits."""
    if value < 0 or len(str(value)) > width:
        raise ValueError(f"{value} does not fit {width} digits")
    return f"{value:0{width}d}"


def text(value: str, width: int) -> str:
    """Text padded right with spaces to exactly `width` characters."""
    if len(value) > width or not value.isascii():
        raise ValueError(f"{value!r} does not fit {width} ASCII characters")
    return value.ljust(width)


def hundredths(value: float) -> int:
    """A torque sent "multiplied by 100 and sent as an integer (2 decimals truncated)"."""
    return math.floor(value * 100 + 1e-6)


def whole(value: float) -> int:
    """An angle in whole degrees (rounded half up)."""
    return math.floor(value + 0.5)


def timestamp(time_s: float) -> str:
    """YYYY-MM-DD:HH:MM:SS in local time."""
    return time.strftime("%Y-%m-%d:%H:%M:%S", time.localtime(time_s))


def parameters(pairs: list[tuple[int, str]]) -> str:
    """A static data field: each value after its two-digit parameter id."""
    return "".join(f"{pid:02d}{value}" for pid, value in pairs)


def variable_field(pid: int, value: str, data_type: int, unit: int, step: int = 0) -> str:
    """One variable data field (Table 4): PID, length, data type, unit, step number, value."""
    return f"{pid:05d}{len(value):03d}{data_type:02d}{unit:03d}{step:04d}{value}"


def header(
    mid: int,
    length: int,
    revision: int = 1,
    *,
    no_ack: bool = False,
    blank_revision_1: bool = False,
) -> bytes:
    """The 20-byte header; revision 1 as three spaces when `blank_revision_1`."""
    rev = "   " if blank_revision_1 and revision == 1 else digits(revision, 3)
    flag = "1" if no_ack else "0"
    return f"{digits(length, 4)}{digits(mid, 4)}{rev}{flag}{' ' * 8}".encode("ascii")


def frame(
    mid: int,
    data: str | bytes,
    revision: int = 1,
    *,
    no_ack: bool = False,
    blank_revision_1: bool = False,
) -> bytes:
    """An ASCII message: header, data field, NUL."""
    body = data.encode("ascii") if isinstance(data, str) else data
    head = header(
        mid, HEADER_SIZE + len(body), revision, no_ack=no_ack, blank_revision_1=blank_revision_1
    )
    return head + body + NUL


def binary_frame(
    mid: int,
    ascii_part: str,
    binary_part: bytes,
    revision: int = 1,
    *,
    nul_separator: bool = True,
    trailing_nul: bool = False,
    blank_revision_1: bool = False,
) -> bytes:
    """A message with a binary part (2.2.4): the length counts everything but a trailing NUL."""
    body = ascii_part.encode("ascii") + (NUL if nul_separator else b"") + binary_part
    head = header(mid, HEADER_SIZE + len(body), revision, blank_revision_1=blank_revision_1)
    return head + body + (NUL if trailing_nul else b"")


@dataclass(frozen=True)
class Message:
    """One message as received: its header's fields, its data field and its bytes."""

    mid: int
    revision: int
    no_ack: bool
    data: bytes
    raw: bytes


@dataclass
class MessageReader:
    """Cuts a byte stream into messages, whatever the reads' boundaries.

    A message is taken as soon as its `length` bytes are in; the NUL that should follow
    is checked when the next byte arrives. What breaks the rules goes to `problems`; a
    length that is not four digits (or under 20) ends the reading: `broken` is set.
    """

    problems: list[str] = field(default_factory=list)
    broken: bool = False
    _buffer: bytearray = field(default_factory=bytearray)
    _nul_due: bool = False

    def feed(self, chunk: bytes) -> list[Message]:
        self._buffer += chunk
        messages: list[Message] = []
        while self._buffer and not self.broken:
            if self._nul_due:
                self._nul_due = False
                if self._buffer[0] == 0:
                    del self._buffer[0]
                    continue
                self.problems.append("a message without its NUL terminator")
            if len(self._buffer) < 4:
                break
            length_text = bytes(self._buffer[:4])
            if not length_text.isdigit() or int(length_text) < HEADER_SIZE:
                self.problems.append(f"unreadable length {length_text!r}")
                self.broken = True
                break
            length = int(length_text)
            if len(self._buffer) < length:
                break
            raw = bytes(self._buffer[:length])
            del self._buffer[:length]
            self._nul_due = True
            message = self._parse(raw)
            if message is not None:
                messages.append(message)
        return messages

    def _parse(self, raw: bytes) -> Message | None:
        mid_text, rev_text = raw[4:8], raw[8:11].strip()
        if not mid_text.isdigit():
            self.problems.append(f"unreadable MID {mid_text!r}")
            return None
        if rev_text and not rev_text.isdigit():
            self.problems.append(f"unreadable revision {raw[8:11]!r} in MID {mid_text!r}")
            revision = -1
        else:
            revision = max(1, int(rev_text or b"1"))
        return Message(int(mid_text), revision, raw[11:12] == b"1", raw[HEADER_SIZE:], raw)
