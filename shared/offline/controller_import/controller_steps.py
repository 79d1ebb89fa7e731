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
file and the key, like every other field of the run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from shared.contract import ControllerFunction, ControllerStep
from shared.errors import InputError

FUNCTIONS_KEY = "tightening functions"
TORQUE_FUNCTION = "TF Torque"
TORSION_RELEASE_KEY = "torsion release"

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
    release = last_graph.get(TORSION_RELEASE_KEY)
    if release is not None and (_not_integer(release) or release < 0):
        raise InputError(
            f"{path}: {where}.{TORSION_RELEASE_KEY}: expected a count of samples, "
            f"got {_kind(release)} {release!r}"
        )
    batch: dict[str, int | None] = {}
    for name, key in BATCH_FIELDS.items():
        value = document.get(key)
        if value is not None and _not_integer(value):
            raise InputError(f"{path}: '{key}': expected an integer, got {_kind(value)} {value!r}")
        batch[name] = value
    return ControllerVerdict(
        result=text(document.get("result")),
        quality_code=text(document.get("quality code")),
        part_id=text(document.get("id code")),
        torque_unit=text(document.get("torque unit")),
        torsion_release_samples=release,
        batch=batch,
    )


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


def _not_integer(value: Any) -> bool:
    return isinstance(value, bool) or not isinstance(value, int)


def _kind(value: Any) -> str:
    return "nothing" if value is None else type(value).__name__
