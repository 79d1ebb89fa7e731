"""The offline trace: CSV with the header ``time_s,torque_nm,angle_deg,force_n`` (contract).

``force_n`` may be empty (torque-only stations, imported controller runs).
This is what ``boltwatch predict`` reads, what ``boltwatch simulate`` and
``boltwatch export`` write. Reading is strict: an empty file, a bad header, a
non-number (or nan/inf), a missing column or a last line cut off is an
InputError that names the file, the line and the column.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

from shared.errors import InputError, naming

HEADER = ("time_s", "torque_nm", "angle_deg", "force_n")

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class Trace:
    """A trace as columns; ``force_n`` is NaN where the file has no value."""

    time_s: FloatArray
    torque_nm: FloatArray
    angle_deg: FloatArray
    force_n: FloatArray

    def __len__(self) -> int:
        return len(self.time_s)

    @property
    def has_force(self) -> bool:
        """True when at least one sample carries a force value."""
        return bool(np.any(~np.isnan(self.force_n)))


def read_trace(path: Path) -> Trace:
    """Read a CSV trace; any malformed line is an InputError naming file and line."""
    text = _read_text(Path(path))
    if not text.strip():
        raise InputError(f"{path}: empty file (expected the header {','.join(HEADER)})")
    last_line = text.count("\n") + (0 if text.endswith("\n") else 1)
    cut_off = not text.endswith(("\n", "\r"))
    columns: list[list[float]] = [[], [], [], []]
    reader = csv.reader(io.StringIO(text, newline=""))
    header = next(reader)
    if tuple(h.strip() for h in header) != HEADER:
        raise InputError(
            f"{path}: line 1: expected the header {','.join(HEADER)}, got {','.join(header)!r}"
        )
    for row in reader:
        line_number = reader.line_num
        if not row:
            continue
        if len(row) != len(HEADER):
            where = f"{path}: line {line_number}"
            if cut_off and line_number == last_line and len(row) < len(HEADER):
                raise InputError(
                    f"{where}: the last line is cut off ({len(row)} of {len(HEADER)} columns, "
                    "no newline at the end of the file)"
                )
            raise InputError(f"{where}: expected {len(HEADER)} columns, got {len(row)}")
        for index, cell in enumerate(row):
            columns[index].append(_parse_cell(cell, path, line_number, index))
    if not columns[0]:
        raise InputError(f"{path}: no samples after the header")
    time_s, torque_nm, angle_deg, force_n = (np.asarray(c, dtype=np.float64) for c in columns)
    return Trace(time_s, torque_nm, angle_deg, force_n)


def _read_text(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError as err:
        raise InputError(f"{path}: file not found") from err
    except UnicodeDecodeError as err:
        raise InputError(f"{path}: not a text file (byte {err.start}: {err.reason})") from err
    except OSError as err:
        raise InputError(f"{path}: cannot be read: {err.strerror}") from err


def _parse_cell(cell: str, path: Path, line_number: int, index: int) -> float:
    text = cell.strip()
    name = HEADER[index]
    if text == "":
        if name == "force_n":
            return math.nan
        raise InputError(f"{path}: line {line_number}: {name} (column {index + 1}) is empty")
    try:
        value = float(text)
    except ValueError as err:
        raise InputError(
            f"{path}: line {line_number}: {name} (column {index + 1}) is not a number: {text!r}"
        ) from err
    if not math.isfinite(value):
        raise InputError(
            f"{path}: line {line_number}: {name} (column {index + 1}) is not finite: {text!r}"
        )
    return value


def write_trace(path: Path, rows: Iterable[tuple[float, float, float, float | None]]) -> int:
    """Write rows ``(time_s, torque_nm, angle_deg, force_n or None)``; returns the row count."""
    count = 0
    with naming(path), Path(path).open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(HEADER)
        for time_s, torque_nm, angle_deg, force_n in rows:
            force_text = "" if force_n is None or math.isnan(force_n) else f"{force_n:.1f}"
            writer.writerow((f"{time_s:.6f}", f"{torque_nm:.4f}", f"{angle_deg:.4f}", force_text))
            count += 1
    return count
