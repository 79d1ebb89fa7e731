"""What each field of a message may hold on the wire: every field of every message is bounded.

The fields of :mod:`shared.contract.messages` are annotated with the aliases below
(``time_ns: TimeNs``); :mod:`shared.contract.codec` refuses a payload with a value
outside its field's bounds (:class:`~shared.errors.InputError` naming the
field) and states the bounds in the JSON schema (``minimum``, ``maximum``,
``maxLength``, ``pattern``). A field without an alias takes its type's
default: an integer fits in 64 signed bits, a number is finite, a string
holds at most :data:`MAX_TEXT_CHARS` characters.

The bounds are the contract's: what any producer of the message may write
(the acquisition, the predictor, ``boltwatch import``, a controller bridge).
A live service narrows them where it knows more: the predictor and the
acquisition take ids only as wide as their station's CAN signals
(:func:`can_id_bounds`), the predictor's core judges measured values against
the station's sensor range, the recorder a sample's values against it and
every time against its arrival.

Why these bounds:

- times (``*_ns``): 0 to 2**63 - 1 ns since the epoch (1970 to 2262-04-11),
  what a signed 64-bit timestamp holds (MCAP, numpy, SQLite, Rerun);
- ids and counts: 0 to 2**63 - 1, what the wear ledger (SQLite INTEGER)
  holds; ``boltwatch import`` takes controller cycles and tool serials that
  wide, so the CAN widths (32-bit RunId, 16-bit ToolId, 8-bit ProgramId) are
  the live channels' narrowing, not the contract's;
- figures: finite (a NaN or an infinity is no figure); ``None`` where the
  message says a figure may be missing;
- measured values of a :class:`~shared.contract.messages.Sample` (and the torque a
  stop decision quotes from one): any number, NaN and infinities included,
  as the contract always allowed: what is plausible depends on the station's
  DBC, and the predictor's core must see an implausible sample to count it
  and, after a long stretch of them, stop the tool (``input_fault``);
- station ids: the key chunk of the station files (:data:`STATION_ID`);
- spindle numbers: 1 to :data:`MAX_SPINDLES` (Open Protocol's two digits); a
  sync id (the controller's id of one synchronised cycle) is an id;
- part ids: 1 to :data:`PART_ID_CHARS` printable ASCII characters, no space
  at either end (:data:`PART_ID`): what a scanner reads off a part (a VIN
  is 17 characters, Open Protocol's VIN field 25, its identifier download
  MID 0150 up to 100); one scanner's padding must not make two parts of one;
- texts: at most :data:`MAX_TEXT_CHARS` characters (a Linux path, PATH_MAX,
  fits in an error text).
"""

from __future__ import annotations

import re
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING, Annotated, Any

import annotated_types
from pydantic import ConfigDict
from pydantic.types import AllowInfNan, StringConstraints

if TYPE_CHECKING:
    from shared.contract.can_database import StationDatabase

INT64_MIN = -(2**63)
INT64_MAX = 2**63 - 1
FLOAT_MAX = sys.float_info.max
MAX_TEXT_CHARS = 4096
#: a station id: a zenoh key chunk, as the station files require (``[station] id``)
STATION_ID = re.compile(r"[A-Za-z0-9_-]{1,64}")
#: a part id: printable ASCII (space to ``~``), neither starting nor ending with a space
PART_ID = re.compile(r"[!-~](?:[ -~]*[!-~])?")
#: the longest part id: the identifier of Open Protocol's MID 0150 (a VIN is 17)
PART_ID_CHARS = 100


@dataclass(frozen=True, slots=True)
class NumberRange(annotated_types.GroupedMetadata):
    """Inclusive range of an integer or a number; ``nan_ok``: NaN and infinities pass too.

    The codec's validator (pydantic) reads it as the constraints it yields.
    """

    low: float
    high: float
    nan_ok: bool = False

    def __iter__(self) -> Iterator[Any]:
        # nan_ok: a NaN, an infinity, or an integer beyond any float fails these two, and
        # the codec's closer look (MessageShape) takes the first two and refuses the third
        if self.nan_ok:
            yield AllowInfNan(True)
        yield annotated_types.Ge(self.low)
        yield annotated_types.Le(self.high)


@dataclass(frozen=True, slots=True)
class TextRange(annotated_types.GroupedMetadata):
    """At most ``max_chars`` characters; with ``pattern``, the whole text matches it."""

    max_chars: int
    pattern: re.Pattern[str] | None = None

    def __iter__(self) -> Iterator[Any]:
        yield annotated_types.MaxLen(self.max_chars)
        if self.pattern is not None:
            yield StringConstraints(pattern=f"^{self.pattern.pattern}$")


#: integer nanoseconds since the Unix epoch
TimeNs = Annotated[int, NumberRange(0, INT64_MAX)]
#: a run, tool or program id (the live channels narrow it to its CAN signal)
Id = Annotated[int, NumberRange(0, INT64_MAX)]
#: how many of something
Count = Annotated[int, NumberRange(0, INT64_MAX)]
#: a measured value as a sensor reported it (judged against the station's sensor range)
Measured = Annotated[float, NumberRange(-FLOAT_MAX, FLOAT_MAX, nan_ok=True)]
#: a station id, the key chunk of ``boltwatch/<station>/...``
StationId = Annotated[str, TextRange(64, STATION_ID)]
#: a part's id (work piece, VIN) as the line scanned it
PartId = Annotated[str, TextRange(PART_ID_CHARS, PART_ID)]
#: the most spindles one station (one multi-spindle system) has: Open Protocol numbers
#: them in two digits (MID 0101)
MAX_SPINDLES = 99
#: a spindle's number in its station, 1 to :data:`MAX_SPINDLES`
SpindleNumber = Annotated[int, NumberRange(1, MAX_SPINDLES)]

DEFAULT_INT = NumberRange(INT64_MIN, INT64_MAX)
DEFAULT_FLOAT = NumberRange(-FLOAT_MAX, FLOAT_MAX)
DEFAULT_TEXT = TextRange(MAX_TEXT_CHARS)
#: an integer with no bound of its own: what 64 signed bits hold
Int64 = Annotated[int, DEFAULT_INT]

#: How every message is read and written (``__pydantic_config__`` of each message type):
#: exactly the JSON types of its schema (no string for a number), no unknown field,
#: figures finite unless a field says ``nan_ok`` (written as JSON's ``NaN`` and
#: ``Infinity``, as Python's json module reads them), texts of at most MAX_TEXT_CHARS.
WIRE_CONFIG = ConfigDict(
    strict=True,
    extra="forbid",
    allow_inf_nan=False,
    ser_json_inf_nan="constants",
    str_max_length=MAX_TEXT_CHARS,
)


#: fields a message of a multi-spindle station has and a single-spindle station's never says
SPINDLE_FIELDS = ("spindle", "sync_id")


def without_unset_spindle(data: dict[str, Any]) -> dict[str, Any]:
    """A message's fields as written on the wire: its spindle fields left out when None, so a
    single-spindle station's message is byte for byte what it was before stations had
    spindles (and what a reader of that time takes: it refuses fields it does not know)."""
    for name in SPINDLE_FIELDS:
        if name in data and data[name] is None:
            del data[name]
    return data


def can_id_bounds(database: StationDatabase) -> dict[str, tuple[int, int]]:
    """``run_id``, ``tool_id``, ``program_id``: what the station's ToolStatus signals carry."""
    bounds = {}
    for field, signal in (("run_id", "RunId"), ("tool_id", "ToolId"), ("program_id", "ProgramId")):
        low, high = database.signal_bounds("ToolStatus", signal)
        bounds[field] = (int(low), int(high))
    return bounds
