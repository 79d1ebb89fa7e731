"""What a CS351 controller says of its own run: each step's result and values, the verdict.

Read from the run's JSON (see :mod:`shared.offline.controller_import.controller_run`) into
:class:`~shared.contract.messages.ControllerStep` values and the run-level fields of
:class:`~shared.contract.messages.ControllerResult`:

- per step: ``name``, ``result`` (OK/NOK), ``quality code``, the number of
  samples of its graph, and every entry of ``tightening functions`` with its
  ``name``, ``nom`` and ``act``;
- per run: ``result``, ``quality code``, ``id code`` (the part), ``torque
  unit``, the batch counters, and the last step's ``torsion release`` (how
  many trailing samples are the tool unloading).

Texts are kept as written (trimmed); a number that is there must be a finite
number (or null), else one :class:`~shared.errors.InputError` naming the
file and the key, like every other field of the run. A counter or identifier
may be written as a number or as its digits in text (``"batch nr": "85"``:
other controllers of the family write their identifiers as text,
:func:`integer_of`).

A step's ``speed`` says which way the tool turned: a negative speed turns it
back. A run whose every step that says its speed turns back is a loosening
(:func:`run_operation`), whatever its functions end on.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from shared.contract import ControllerFunction, ControllerStep, RunOperation
from shared.errors import InputError

FUNCTIONS_KEY = "tightening functions"
TORQUE_FUNCTION = "TF Torque"
TORSION_RELEASE_KEY = "torsion release"
SPEED_KEY = "speed"
#: an integer written as text: digits, a sign before them, spaces around them
INTEGER_TEXT = re.compile(r"\s*[+-]?[0-9]+\s*")

#: ControllerResult field -> the controller's batch key.
BATCH_FIELDS = {
    "batch_number": "batch nr",
    "batch_ok": "batch OK",
    "batch_nok": "batch NOK",
    "batch_max_ok": "batch max OK",
    "batch_max_nok": "batch max NOK",
    "batch_canceled": "batch canceled",
    "batch_direction_ok": "batch direction OK",
    "batch_direction_nok": "batch direction NOK",
}


@dataclass(frozen=True, slots=True)
class ControllerVerdict:
    """The run-level fields of the controller's result (everything but the steps)."""

    result: str
    quality_code: str
    part_id: str
    torque_unit: str
    torsion_release_samples: int | None
    batch: dict[str, int | None]  # ControllerResult field name -> value


def read_step(path: Path, where: str, step: dict[str, Any], samples: int) -> ControllerStep:
    """One step's name, result, quality code and functions; ``where`` names it."""
    functions = step.get(FUNCTIONS_KEY, [])
    if not isinstance(functions, list):
        raise InputError(
            f"{path}: {where}.{FUNCTIONS_KEY}: expected a list, got {_kind(functions)}"
        )
    return ControllerStep(
        name=text(step.get("name")),
        result=text(step.get("result")),
        quality_code=text(step.get("quality code")),
        samples=samples,
        functions=[
            _function(path, f"{where}.{FUNCTIONS_KEY}[{index}]", entry)
            for index, entry in enumerate(functions)
        ],
    )


def read_verdict(
    path: Path, document: dict[str, Any], last_graph: dict[str, Any], where: str
) -> ControllerVerdict:
    """The run's verdict fields; ``last_graph`` is the last step's graph (``where`` its key)."""
    written = last_graph.get(TORSION_RELEASE_KEY)
    release = integer_of(written)
    if written is not None and (release is None or release < 0):
        raise InputError(
            f"{path}: {where}.{TORSION_RELEASE_KEY}: expected a count of samples, "
            f"got {_kind(written)} {written!r}"
        )
    batch: dict[str, int | None] = {}
    for name, key in BATCH_FIELDS.items():
        value = document.get(key)
        number = integer_of(value)
        if value is not None and number is None:
            raise InputError(f"{path}: '{key}': {integer_expected(value)}")
        batch[name] = number
    return ControllerVerdict(
        result=text(document.get("result")),
        quality_code=text(document.get("quality code")),
        part_id=text(document.get("id code")),
        torque_unit=text(document.get("torque unit")),
        torsion_release_samples=release,
        batch=batch,
    )


def read_speed(path: Path, where: str, step: dict[str, Any]) -> float | None:
    """The step's ``speed`` (negative: turning back); None when it gives none."""
    value = step.get(SPEED_KEY)
    if value is None:
        return None
    if isinstance(value, str):
        try:
            number = float(value)
        except ValueError:
            number = math.nan
    elif isinstance(value, int | float) and not isinstance(value, bool):
        number = float(value)
    else:
        number = math.nan
    if not math.isfinite(number):
        raise InputError(f"{path}: {where}.{SPEED_KEY}: expected a finite number, got {value!r}")
    return number


def run_operation(speeds: list[float | None]) -> RunOperation:
    """A loosening when every step that says its speed turns back, else a tightening."""
    said = [speed for speed in speeds if speed is not None and speed != 0.0]
    return "loosening" if said and all(speed < 0.0 for speed in said) else "tightening"


def integer_of(value: Any) -> int | None:
    """``value`` as an integer: a JSON integer, or its digits as text; None if it is neither."""
    if isinstance(value, int) and not isinstance(value, bool):
        return value
    if isinstance(value, str) and INTEGER_TEXT.fullmatch(value):
        return int(value)
    return None


def integer_expected(value: Any) -> str:
    """What the error of a field that must hold an integer says of ``value``."""
    if isinstance(value, str):
        return f"expected an integer (as a number or as its digits), got str {value!r}"
    return f"expected an integer, got {_kind(value)} {value!r}"


def torque_function(step: ControllerStep) -> ControllerFunction | None:
    """The step's ``TF Torque`` (the torque that ends it), if it has one."""
    return next((f for f in step.functions if f.name == TORQUE_FUNCTION), None)


def text(value: Any) -> str:
    """A header or step text as the controller wrote it, trimmed; "" when absent."""
    return "" if value is None else str(value).strip()


def _function(path: Path, where: str, entry: Any) -> ControllerFunction:
    if not isinstance(entry, dict):
        raise InputError(f"{path}: {where}: expected an object, got {_kind(entry)}")
    return ControllerFunction(
        name=text(entry.get("name")),
        nominal=_optional_number(path, where, entry, "nom"),
        actual=_optional_number(path, where, entry, "act"),
    )


def _optional_number(path: Path, where: str, entry: dict[str, Any], key: str) -> float | None:
    value = entry.get(key)
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise InputError(f"{path}: {where}.{key}: expected a finite number, got {value!r}")
    return float(value)


def _kind(value: Any) -> str:
    return "nothing" if value is None else type(value).__name__
