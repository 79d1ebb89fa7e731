"""Trace curves of a tightening and their MID 0900 messages.

Layout source: Open Protocol Specification R2.8.0 (Atlas Copco 9836 4415 01), 5.27.1 MID 0900
Trace curve data message, Table 157 (revision 1): result data identifier (10), time stamp
(19), number of PIDs (3) and their variable data fields, trace type (2), transducer type
(2), unit (3), number of parameter data fields (3) and the fields, number of resolution
fields (3) and each resolution field (first index 5, last index 5, length 3, data type 2,
unit 3, time value), number of trace samples (5), a NUL, then each sample as 2 binary bytes.
Revision 2 (R2.16.0, Table 207) adds the request MID (4) after the unit. Scaling (6.4,
Table 163): PID 02213 "Physical value = Binary value / Coefficient", PID 02214 "Physical
value = Binary value * Coefficient". Data types (6.1, Table 161): 01 UI, 03 F, 04 S. Units
(6.3, Table 162): 001 N·m, 050 degree, 200 s, 202 ms. The message end rules of 2.2.4 are in
`openprotocol_wire.binary_frame`.

The specification names no byte order for the samples: public integrators read them big
endian (node-open-protocol-v2's helpers.processTraceSamples, OpenProtocolInterpreter's
pull request #43), and a capture of a real controller published with node-open-protocol-v2
(src/MID0900_example.json) shows a first-level PID count of 000, the PIDs 01000, 00010,
01202 and 02214 ("0.001417", type F) with the trace, and one resolution field from index 0
to the last sample, type F, unit 202. Both byte orders are a setting here.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from typing import Literal

from tests.support.openprotocol_wire import binary_frame, digits, timestamp, variable_field

ANGLE_TRACE = 1
TORQUE_TRACE = 2
SAMPLE_PERIOD_S = 0.001

ByteOrder = Literal["big", "little"]
Scaling = Literal["coefficient", "divisor", "none"]


@dataclass(frozen=True)
class Curves:
    """Torque and angle sampled every `SAMPLE_PERIOD_S`, as the tool measured them."""

    torque_nm: tuple[float, ...]
    angle_deg: tuple[float, ...]


def make_curves(final_torque_nm: float, final_angle_deg: float) -> Curves:
    """A rundown then a tightening ramp with three small stick-slip drops.

    The torque peaks at its last sample, at `final_torque_nm`; the angle rises steadily to
    `final_angle_deg` at the last sample. 300 to 1000 samples, more for larger angles.
    """
    count = min(1000, max(300, int(final_angle_deg * 2) + 200))
    rundown = int(count * 0.45)
    ramp = count - rundown
    drops = {int(ramp * share) for share in (0.35, 0.6, 0.8)}
    torque: list[float] = []
    for i in range(count):
        if i < rundown:
            torque.append(0.05 * final_torque_nm * i / rundown)
            continue
        j = i - rundown + 1
        value = final_torque_nm * (0.05 + 0.95 * j / ramp)
        if any(0 <= j - start < 6 for start in drops) and j < ramp:
            value *= 0.96  # the joint sticks, then slips: the torque drops for 6 ms
        torque.append(value)
    angle = [final_angle_deg * (i + 1) / count for i in range(count)]
    return Curves(tuple(torque), tuple(angle))


@dataclass(frozen=True)
class TraceOptions:
    """How a MID 0900 is written; `trace_wire` overrides any of these for hostile tests."""

    byte_order: ByteOrder = "big"
    scaling: Scaling = "coefficient"
    nul_separator: bool = True
    trailing_nul: bool = False
    time_unit: Literal["ms", "s"] = "ms"
    resolution: bool = True
    revision: int = 1
    time_value: str | None = None
    coefficient: str | None = None
    samples: tuple[int, ...] | None = None
    declared_samples: int | None = None
    result_data_id: str | None = None
    blank_revision_1: bool = False


def scale_factor(values: tuple[float, ...]) -> int:
    """The largest of 100, 10 and 1 that keeps every value × factor within 16 bits."""
    peak = max((abs(v) for v in values), default=0.0)
    return next((f for f in (100, 10) if peak * f <= 32767), 1)


def trace(
    tightening_id: int,
    time_s: float,
    trace_type: int,
    values: tuple[float, ...],
    context: tuple[int, str, str],
    options: TraceOptions,
) -> bytes:
    """One MID 0900 message; `context` is (Pset, VIN, tool serial number)."""
    pset, vin, tool_serial = context
    factor = scale_factor(values)
    samples = (
        options.samples if options.samples is not None else tuple(round(v * factor) for v in values)
    )
    pids = [
        variable_field(1000, str(pset), 1, 0),
        variable_field(10, vin.ljust(25), 4, 0),
        variable_field(1202, tool_serial, 4, 0),
    ]
    if options.scaling == "coefficient":
        pids.append(variable_field(2214, options.coefficient or f"{1 / factor:.6f}", 3, 0))
    elif options.scaling == "divisor":
        pids.append(variable_field(2213, options.coefficient or str(factor), 1, 0))
    if options.time_unit == "ms":
        time_value, time_unit = options.time_value or f"{SAMPLE_PERIOD_S * 1000:.6f}", 202
    else:
        time_value, time_unit = options.time_value or f"{SAMPLE_PERIOD_S:.6f}", 200
    resolution = ""
    if options.resolution:
        resolution = (
            f"{digits(0, 5)}{digits(len(samples) - 1, 5)}{len(time_value):03d}03"
            f"{time_unit:03d}{time_value}"
        )
    unit = 1 if trace_type == TORQUE_TRACE else 50
    ascii_part = "".join(
        [
            options.result_data_id or digits(tightening_id, 10),
            timestamp(time_s),
            "000",  # no PIDs common to all traces
            f"{trace_type:02d}01{unit:03d}",  # trace type, transducer 1, unit
            "0008" if options.revision >= 2 else "",  # request MID (revision 2)
            f"{len(pids):03d}",
            *pids,
            "001" if options.resolution else "000",
            resolution,
            digits(
                len(samples) if options.declared_samples is None else options.declared_samples, 5
            ),
        ]
    )
    fmt = (">" if options.byte_order == "big" else "<") + f"{len(samples)}h"
    return binary_frame(
        900,
        ascii_part,
        struct.pack(fmt, *samples),
        options.revision,
        nul_separator=options.nul_separator,
        trailing_nul=options.trailing_nul,
        blank_revision_1=options.blank_revision_1,
    )
