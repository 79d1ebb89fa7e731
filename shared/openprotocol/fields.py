"""Fixed-width data fields: the layout of a message revision, read and written.

Most Open Protocol data is a row of fields, each optionally preceded by its
two-digit parameter id ("01", "02", ...) and padded to a fixed width: numbers
right-aligned with zeros, text left-aligned with spaces. A :class:`Spec` says
one field; a layout is the tuple of a revision's specs in wire order.

Kinds:

- ``int``: digits (spaces around are tolerated on reading), in [``low``, ``high``]
  (``high`` defaults to what the width can hold); a field whose ``low`` is below
  0 takes a leading minus, within the width ("-0015": a press's stroke, 0101);
- ``centi``: a decimal sent as an integer number of hundredths (torques in Nm:
  "001234" is 12.34 Nm), read as float; written "multiplied by 100 and sent as
  an integer (2 decimals truncated)", as the specification words every such
  field of 0041, 0061 and 0065: 12.349 Nm is "001234", never "001235" (the
  decimal as written, so 0.29 is "000029", not the float's 28.999...);
- ``flag``: one digit 0/1, read as bool;
- ``enum``: digits read as the ``enum`` IntEnum given; other values refused;
- ``text``: characters (latin-1), written left-aligned (padded with spaces at
  the end); spaces stripped at both ends on reading: controllers also pad on
  the left (OpenProtocolInterpreter's test ``TestMid0061.Mid0061Revision2``
  carries the tool serial "      C0761275", ``TestMid0076.Mid0076Revision2``
  the error code " E851"; node-open-protocol trims both ends of every text);
- ``timestamp``: ``YYYY-MM-DD:HH:MM:SS`` kept as text, checked to exist.

Data longer than the layout is tolerated (fields of a later revision); shorter
is refused, as is a wrong parameter id.
"""

from __future__ import annotations

import decimal
import enum
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import ClassVar, Literal, Self

from shared.openprotocol.dialect import DEFAULT_DIALECT, Dialect
from shared.openprotocol.errors import OpenProtocolError
from shared.openprotocol.timestamps import parse_timestamp

Kind = Literal["int", "centi", "flag", "enum", "text", "timestamp"]


@dataclass(frozen=True, slots=True)
class Spec:
    """One field: the message attribute, the specification's name, its width and kind."""

    attr: str
    label: str
    width: int
    kind: Kind = "int"
    pid: int | None = None
    low: int = 0
    high: int | None = None
    enum: type[enum.IntEnum] | None = None

    @property
    def wire_width(self) -> int:
        return self.width + (0 if self.pid is None else 2)


Layout = tuple[Spec, ...]


def numbered(*specs: Spec) -> Layout:
    """``specs`` given parameter ids 01, 02, ... in order."""
    return tuple(
        Spec(s.attr, s.label, s.width, s.kind, index, s.low, s.high, s.enum)
        for index, s in enumerate(specs, start=1)
    )


def layout_width(layout: Layout) -> int:
    return sum(spec.wire_width for spec in layout)


def decode_fields(data: bytes, layout: Layout, mid: int, revision: int) -> dict[str, object]:
    """The attribute values of ``data`` read by ``layout``; OpenProtocolError if malformed."""
    values: dict[str, object] = {}
    at = 0
    for spec in layout:
        if len(data) < at + spec.wire_width:
            why = f"data ends at byte {len(data)}, the field needs {spec.wire_width} from {at}"
            raise OpenProtocolError(mid, spec.label, why, revision=revision)
        if spec.pid is not None:
            pid = data[at : at + 2]
            if pid != f"{spec.pid:02d}".encode():
                why = f"parameter id '{pid.decode('latin-1')}' where {spec.pid:02d} is due"
                raise OpenProtocolError(mid, spec.label, why, revision=revision)
            at += 2
        text = data[at : at + spec.width].decode("latin-1")
        at += spec.width
        try:
            values[spec.attr] = _read(spec, text)
        except ValueError as err:
            raise OpenProtocolError(mid, spec.label, str(err), revision=revision) from None
    return values


def encode_fields(values: Mapping[str, object], layout: Layout, mid: int, revision: int) -> bytes:
    """The data bytes of ``values`` written by ``layout``; OpenProtocolError if one does not fit."""
    parts: list[str] = []
    for spec in layout:
        value = values[spec.attr]
        if value is None:
            why = f"is needed by revision {revision}"
            raise OpenProtocolError(mid, spec.label, why, revision=revision)
        try:
            text = _write(spec, value)
        except ValueError as err:
            raise OpenProtocolError(mid, spec.label, str(err), revision=revision) from None
        parts.append(("" if spec.pid is None else f"{spec.pid:02d}") + text)
    return "".join(parts).encode("latin-1")  # each part was checked to be latin-1


def _number(spec: Spec, text: str) -> int:
    stripped = text.strip(" ")
    negative = spec.low < 0 and stripped.startswith("-")  # a field that may be below 0
    digits = stripped[1:] if negative else stripped
    if not digits.isascii() or not digits.isdigit():
        raise ValueError(f"'{text}' is not a number")
    return -int(digits) if negative else int(digits)


def _in_range(spec: Spec, number: int, shown: str) -> int:
    high = 1 if spec.kind == "flag" else 10**spec.width - 1 if spec.high is None else spec.high
    if not spec.low <= number <= high:
        raise ValueError(f"{shown} is not in [{spec.low}, {high}]")
    return number


def _read(spec: Spec, text: str) -> object:
    if spec.kind == "text":
        return text.strip(" ")
    if spec.kind == "timestamp":
        parse_timestamp(text)
        return text
    number = _in_range(spec, _number(spec, text), f"'{text}'")
    if spec.kind == "centi":
        return number / 100
    if spec.kind == "flag":
        return bool(number)
    if spec.kind == "enum":
        assert spec.enum is not None
        try:
            return spec.enum(number)
        except ValueError:
            allowed = ", ".join(f"{m.value} {m.name}" for m in spec.enum)
            raise ValueError(f"'{text}' is not one of {allowed}") from None
    return number


def _write(spec: Spec, value: object) -> str:
    if spec.kind == "text":
        text = str(value)
        if len(text) > spec.width:
            raise ValueError(f"'{text}' is longer than {spec.width} characters")
        try:
            text.encode("latin-1")
        except UnicodeEncodeError:
            raise ValueError(f"'{text}' is not latin-1") from None
        return text.ljust(spec.width)
    if spec.kind == "timestamp":
        text = str(value)
        parse_timestamp(text)
        return text
    if spec.kind == "centi":
        if not isinstance(value, int | float) or not math.isfinite(value):
            raise ValueError(f"{value!r} is not a number")
        number = _hundredths_truncated(value)
        if not 0 <= number < 10**spec.width:
            raise ValueError(f"{value} is not in [0, {(10**spec.width - 1) / 100}]")
        return f"{number:0{spec.width}d}"
    if not isinstance(value, int):  # bool and IntEnum are
        raise ValueError(f"{value!r} is not a whole number")
    number = int(value)
    if spec.kind == "enum" and spec.enum is not None and number not in set(spec.enum):
        raise ValueError(f"{number} is not a {spec.enum.__name__}")
    _in_range(spec, number, f"{number}")
    return f"{number:0{spec.width}d}"


def _hundredths_truncated(value: float) -> int:
    """``value`` * 100 with the decimals after the second cut off (toward zero), taken
    from the shortest decimal that reads back as ``value`` (``repr``), not the binary
    float: 0.29 is 29 hundredths, 12.349 is 1234."""
    exact = decimal.Decimal(repr(float(value))).scaleb(2)
    return int(exact.to_integral_value(rounding=decimal.ROUND_DOWN))


class LayoutMessage:
    """Mixin of a message whose data is one layout per revision (``LAYOUTS``).

    Subclasses are frozen dataclasses with a ``revision`` field and one field
    per layout attribute; those a revision lacks default to None.
    """

    __slots__ = ()
    MID: ClassVar[int]
    LAYOUTS: ClassVar[Mapping[int, Layout]]
    #: a message with no data at any revision whose revision asks nothing of the answer
    #: (an acknowledge, an unsubscribe, 0003, 9999): read and written at every revision
    ANY_REVISION: ClassVar[bool] = False

    @classmethod
    def revisions(cls) -> tuple[int, ...]:
        return tuple(sorted(cls.LAYOUTS))

    @classmethod
    def layout(cls, revision: int) -> Layout:
        if cls.ANY_REVISION:
            return ()
        return cls.LAYOUTS[revision]

    @classmethod
    def from_data(cls, data: bytes, revision: int, dialect: Dialect = DEFAULT_DIALECT) -> Self:
        values = decode_fields(data, cls.layout(revision), cls.MID, revision)
        build: Callable[..., Self] = cls
        return build(revision=revision, **values)

    def to_data(self, revision: int, dialect: Dialect = DEFAULT_DIALECT) -> bytes:
        layout = self.layout(revision)
        values = {spec.attr: getattr(self, spec.attr) for spec in layout}
        return encode_fields(values, layout, self.MID, revision)
