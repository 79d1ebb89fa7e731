"""What real controllers differ on when writing: one setting per controller.

Reading accepts every form; writing needs one. Defaults and why:

- ``header_fill="space"``: unused header fields (station, spindle, sequence,
  message parts) as spaces: the specification says "space or zero: not used"
  and OpenProtocolInterpreter's header writer writes spaces.
- ``nul_terminator=True``: the specification ends every message with a NUL.
- ``trace_byte_order="big"``: 0900 samples are read big-endian by all three
  public readings (node-open-protocol ``processTraceSamples``,
  OpenProtocolInterpreter's 0900 parser, the Rust crate's ``TraceSample``).
- ``trace_nul_separator=True``: the specification puts a NUL between the
  0900 ASCII part and its samples; reading takes both forms.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from shared.openprotocol.framing import DEFAULT_HEADER_FILL, HeaderFill

TraceByteOrder = Literal["big", "little"]


@dataclass(frozen=True, slots=True)
class Dialect:
    """How to write (and, for 0900 samples, read) for one controller."""

    header_fill: HeaderFill = DEFAULT_HEADER_FILL
    nul_terminator: bool = True
    trace_byte_order: TraceByteOrder = "big"
    trace_nul_separator: bool = True


DEFAULT_DIALECT = Dialect()
