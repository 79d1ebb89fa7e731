"""0900 trace curve data: an ASCII part, then binary samples with their scaling.

Revision 1, no parameter ids in the fixed part (the specification, Open
Protocol 2.8.0, 5.27.1, Table 157)::

    result data identifier (10: the tightening id) | time stamp (19)
    | number of PID data fields (3) | PID data fields
    | trace type (2) | transducer type (2) | unit (3)
    | number of parameter data fields (3) | parameter data fields
    | number of resolution fields (3) | resolution fields
    | number of trace samples (5) | NUL | samples, 2 bytes each

    data field:       PID (5) | length (3) | data type (2) | unit (3) | step no. (4) | value
    resolution field: first index (5) | last index (5) | length (3) | data type (2)
                      | unit (3) | time value (the time between two samples)

Samples are signed 16-bit integers, big-endian unless ``Dialect.trace_byte_order``
says little; a parameter data field gives their scaling: PID 02214
"coefficient", value = raw * coefficient, or PID 02213, value = raw / divisor.
Time units: 200 s, 201 min, 202 ms, 203 h. Trace types (the Rust crate's
``TraceType``): 1 angle, 2 torque, 3 current, 4 gradient, 5 stroke, 6 force.
Read too: a NUL between the ASCII part and the samples or none (the count of
samples tells which), a NUL after the samples counted in the length or not.
Why signed and big-endian, from which sources (they disagree on the sign):
``docs/explanation/openprotocol-bridge.md``, "Reading what the sources disagree on".
"""

from __future__ import annotations

import dataclasses
import enum
import math
import struct
from dataclasses import dataclass
from typing import ClassVar, Final, Self

from shared.openprotocol.dialect import DEFAULT_DIALECT, Dialect, TraceByteOrder
from shared.openprotocol.errors import OpenProtocolError
from shared.openprotocol.timestamps import parse_timestamp


class TraceType(enum.IntEnum):
    ANGLE = 1
    TORQUE = 2
    CURRENT = 3
    GRADIENT = 4
    STROKE = 5
    FORCE = 6


UNIT_NM: Final = 1
UNIT_DEGREE: Final = 50
TIME_UNIT_S: Final = {200: 1.0, 201: 60.0, 202: 0.001, 203: 3600.0}
COEFFICIENT_PID: Final = 2214  # value = raw * coefficient
DIVISOR_PID: Final = 2213  # value = raw / divisor
DATA_TYPE_FLOAT: Final = 3
_INT16 = (-32768, 32767)
_MID = 900


@dataclass(frozen=True, slots=True)
class VariableField:
    """A 0900 PID or parameter data field."""

    pid: int
    value: str
    data_type: int = DATA_TYPE_FLOAT
    unit: int = 0
    step: int = 0


@dataclass(frozen=True, slots=True)
class ResolutionField:
    """The time between two samples from ``first_index`` to ``last_index``, in ``unit``."""

    first_index: int
    last_index: int
    value: str
    unit: int = 200
    data_type: int = DATA_TYPE_FLOAT

    @property
    def step_s(self) -> float:
        return float(self.value) * TIME_UNIT_S[self.unit]


class _Cursor:
    def __init__(self, data: bytes) -> None:
        self.data = data
        self.at = 0

    def text(self, width: int, field: str) -> str:
        if len(self.data) < self.at + width:
            why = f"data ends at byte {len(self.data)}, the field needs {width} from {self.at}"
            raise OpenProtocolError(_MID, field, why, revision=1)
        text = self.data[self.at : self.at + width].decode("latin-1")
        self.at += width
        return text

    def number(self, width: int, field: str) -> int:
        text = self.text(width, field)
        if not text.isascii() or not text.isdigit():
            raise OpenProtocolError(_MID, field, f"'{text}' is not a number", revision=1)
        return int(text)

    def variable_fields(self, field: str) -> tuple[VariableField, ...]:
        fields = []
        for _ in range(self.number(3, f"number of {field}s")):
            pid = self.number(5, f"{field} pid")
            length = self.number(3, f"{field} length")
            data_type = self.number(2, f"{field} data type")
            unit = self.number(3, f"{field} unit")
            step = self.number(4, f"{field} step number")
            value = self.text(length, f"{field} {pid:05d} value").strip(" ")
            fields.append(VariableField(pid, value, data_type, unit, step))
        return tuple(fields)

    def resolution_fields(self) -> tuple[ResolutionField, ...]:
        fields = []
        for _ in range(self.number(3, "number of resolution fields")):
            first = self.number(5, "resolution first index")
            last = self.number(5, "resolution last index")
            length = self.number(3, "resolution length")
            data_type = self.number(2, "resolution data type")
            unit = self.number(3, "resolution unit")
            value = self.text(length, "resolution time value").strip(" ")
            resolution = ResolutionField(first, last, value, unit, data_type)
            _check_resolution(resolution)
            fields.append(resolution)
        return tuple(fields)


def _check_resolution(field: ResolutionField) -> None:
    if field.unit not in TIME_UNIT_S:
        why = f"{field.unit} is not a time unit ({', '.join(map(str, TIME_UNIT_S))})"
        raise OpenProtocolError(_MID, "resolution unit", why, revision=1)
    try:
        step = float(field.value)
    except ValueError:
        step = math.nan
    if not math.isfinite(step) or step <= 0:
        why = f"'{field.value}' is not a positive number"
        raise OpenProtocolError(_MID, "resolution time value", why, revision=1)


def _scale(fields: tuple[VariableField, ...]) -> float:
    """value = raw * the returned factor, from the coefficient or divisor parameter."""
    for field in fields:
        if field.pid in (COEFFICIENT_PID, DIVISOR_PID):
            label = f"parameter {field.pid:05d} value"
            try:
                number = float(field.value)
            except ValueError:
                number = math.nan
            if not math.isfinite(number) or number <= 0:
                why = f"'{field.value}' is not a positive number"
                raise OpenProtocolError(_MID, label, why, revision=1)
            return number if field.pid == COEFFICIENT_PID else 1 / number
    why = f"no coefficient ({COEFFICIENT_PID:05d}) or divisor ({DIVISOR_PID:05d}) parameter"
    raise OpenProtocolError(_MID, "parameter data fields", why, revision=1)


@dataclass(frozen=True, slots=True, kw_only=True)
class TraceCurve:
    """0900: one curve of one tightening; ``samples`` in ``unit`` (1 Nm, 50 degrees...)."""

    MID: ClassVar[int] = _MID
    result_id: int
    timestamp: str
    trace_type: int
    unit: int
    samples: tuple[float, ...]
    parameter_fields: tuple[VariableField, ...]
    resolution_fields: tuple[ResolutionField, ...]
    transducer_type: int = 0
    pid_fields: tuple[VariableField, ...] = ()
    revision: int = 1
    #: the samples as they came (2 bytes each; empty for a curve built, not read)
    sample_bytes: bytes = dataclasses.field(default=b"", compare=False, repr=False)

    def read_samples(self, byte_order: TraceByteOrder, factor: float) -> tuple[float, ...]:
        """The samples as they came, read in ``byte_order`` times ``factor``."""
        order = ">" if byte_order == "big" else "<"
        raw = struct.unpack(f"{order}{len(self.sample_bytes) // 2}h", self.sample_bytes)
        return tuple(value * factor for value in raw)

    @classmethod
    def build(
        cls,
        *,
        result_id: int,
        timestamp: str,
        trace_type: int,
        unit: int,
        samples: tuple[float, ...],
        time_step_s: float,
        coefficient: float,
    ) -> Self:
        """A curve sampled every ``time_step_s`` seconds, raw = value / ``coefficient``."""
        return cls(
            result_id=result_id,
            timestamp=timestamp,
            trace_type=trace_type,
            unit=unit,
            samples=samples,
            parameter_fields=(VariableField(COEFFICIENT_PID, repr(float(coefficient))),),
            resolution_fields=(
                ResolutionField(1, max(len(samples), 1), repr(float(time_step_s)), 200),
            ),
        )

    @property
    def coefficient(self) -> float:
        """value = raw sample * coefficient."""
        return _scale(self.parameter_fields)

    @property
    def time_step_s(self) -> float:
        """The time between two samples (of the first resolution field), in seconds."""
        if not self.resolution_fields:
            raise OpenProtocolError(_MID, "resolution fields", "none given", revision=1)
        return self.resolution_fields[0].step_s

    @classmethod
    def revisions(cls) -> tuple[int, ...]:
        return (1,)

    @classmethod
    def from_data(cls, data: bytes, revision: int, dialect: Dialect = DEFAULT_DIALECT) -> Self:
        cursor = _Cursor(data)
        result_id = cursor.number(10, "result data identifier")
        timestamp = cursor.text(19, "time stamp")
        try:
            parse_timestamp(timestamp)
        except ValueError as err:
            raise OpenProtocolError(_MID, "time stamp", str(err), revision=1) from None
        pid_fields = cursor.variable_fields("PID data field")
        trace_type = cursor.number(2, "trace type")
        transducer_type = cursor.number(2, "transducer type")
        unit = cursor.number(3, "unit")
        parameter_fields = cursor.variable_fields("parameter data field")
        resolution_fields = cursor.resolution_fields()
        count = cursor.number(5, "number of trace samples")
        rest = data[cursor.at :]
        separator = len(rest) - 2 * count
        if separator in (1, 2) and rest[0] == 0 and (separator == 1 or rest[-1] == 0):
            rest = rest[1 : 1 + 2 * count]  # the NUL before the samples (and one counted after)
        elif separator != 0:
            why = f"{len(rest)} bytes where {count} samples need {2 * count} (+ 1 NUL)"
            raise OpenProtocolError(_MID, "trace samples", why, revision=1)
        order = ">" if dialect.trace_byte_order == "big" else "<"
        raw = struct.unpack(f"{order}{count}h", rest)
        factor = _scale(parameter_fields) if count else 1.0
        return cls(
            result_id=result_id,
            timestamp=timestamp,
            trace_type=trace_type,
            unit=unit,
            samples=tuple(value * factor for value in raw),
            parameter_fields=parameter_fields,
            resolution_fields=resolution_fields,
            transducer_type=transducer_type,
            pid_fields=pid_fields,
            revision=revision,
            sample_bytes=bytes(rest),
        )

    def to_data(self, revision: int, dialect: Dialect = DEFAULT_DIALECT) -> bytes:
        try:
            parse_timestamp(self.timestamp)
        except ValueError as err:
            raise OpenProtocolError(_MID, "time stamp", str(err), revision=1) from None
        for resolution in self.resolution_fields:
            _check_resolution(resolution)
        _fits(self.result_id, 10, "result data identifier")
        _fits(self.trace_type, 2, "trace type")
        _fits(self.transducer_type, 2, "transducer type")
        _fits(self.unit, 3, "unit")
        _fits(len(self.samples), 5, "number of trace samples")
        ascii_part = (
            f"{self.result_id:010d}{self.timestamp}"
            + _variable_text(self.pid_fields, "PID data field")
            + f"{self.trace_type:02d}{self.transducer_type:02d}{self.unit:03d}"
            + _variable_text(self.parameter_fields, "parameter data field")
            + _resolution_text(self.resolution_fields)
            + f"{len(self.samples):05d}"
        )
        factor = _scale(self.parameter_fields) if self.samples else 1.0
        raw = [_raw(value, factor) for value in self.samples]
        order = ">" if dialect.trace_byte_order == "big" else "<"
        separator = b"\x00" if dialect.trace_nul_separator else b""
        return ascii_part.encode("latin-1") + separator + struct.pack(f"{order}{len(raw)}h", *raw)


def _fits(value: int, width: int, field: str) -> None:
    if not 0 <= value < 10**width:
        why = f"{value} is not in [0, {10**width - 1}]"
        raise OpenProtocolError(_MID, field, why, revision=1)


def _raw(value: float, factor: float) -> int:
    raw = round(value / factor) if math.isfinite(value) else _INT16[1] + 1
    if not _INT16[0] <= raw <= _INT16[1]:
        low, high = _INT16[0] * factor, _INT16[1] * factor
        why = f"{value} is not in [{low}, {high}] (16 bits at coefficient {factor})"
        raise OpenProtocolError(_MID, "trace samples", why, revision=1)
    return raw


def _variable_text(fields: tuple[VariableField, ...], field: str) -> str:
    _fits(len(fields), 3, f"number of {field}s")
    parts = [f"{len(fields):03d}"]
    for f in fields:
        for value, width, name in ((f.pid, 5, "pid"), (len(f.value), 3, "length"),
                                   (f.data_type, 2, "data type"), (f.unit, 3, "unit"),
                                   (f.step, 4, "step number")):  # fmt: skip
            _fits(value, width, f"{field} {name}")
        parts.append(f"{f.pid:05d}{len(f.value):03d}{f.data_type:02d}{f.unit:03d}{f.step:04d}")
        parts.append(f.value)
    return "".join(parts)


def _resolution_text(fields: tuple[ResolutionField, ...]) -> str:
    _fits(len(fields), 3, "number of resolution fields")
    parts = [f"{len(fields):03d}"]
    for f in fields:
        for value, width, name in ((f.first_index, 5, "first index"),
                                   (f.last_index, 5, "last index"), (len(f.value), 3, "length"),
                                   (f.data_type, 2, "data type")):  # fmt: skip
            _fits(value, width, f"resolution {name}")
        parts.append(
            f"{f.first_index:05d}{f.last_index:05d}{len(f.value):03d}{f.data_type:02d}"
            f"{f.unit:03d}{f.value}"
        )
    return "".join(parts)
