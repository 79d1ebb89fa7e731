"""Runs of another controller of the CS351's family, made from the real CS351 runs.

A cordless nutrunner of the same family writes the same JSON layout, with its
identifiers as text (``"tool serial": "520000905"``, ``"batch nr": "85"``),
and exports loosenings as well as tightenings. The test data stays small: each
run here is a real CS351 run of ``tests/data/cs351-real-runs`` copied into a
test's folder with the fields that tool writes otherwise:

- :func:`with_text_identifiers`: the serial and the batch number as text;
- :func:`loosening_of`: the real run's curve turned back (its last sample
  first, the way a loosening meets the joint: the breakaway at the final
  torque, then the run-out through the formed thread), turning and loaded
  counter-clockwise (angle and torque negative), one step at a negative
  speed ending on an angle (``TF Angle``), no torque function;
- :func:`at_resolution`: the run's torque written to a coarser resolution
  (two decimals: 0.01 Nm, as a tool with a 12 Nm nominal torque may write it).
"""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path
from typing import Any

from tests.support.paths import PROJECT_REAL_RUNS

#: a real class-1 run (527 samples, final step to 1.4 Nm)
SOURCE_RUN = PROJECT_REAL_RUNS / "Ch_000001596339.json"
OTHER_SERIAL = "520000905"
OTHER_BATCH = "85"
OTHER_NOMINAL_NM = 12
LOOSENING_SPEED = -600  # the thread-forming step's speed, turned back
LOOSENING_RUN_ID = 2_000_001


def _document(source: Path) -> dict[str, Any]:
    document: dict[str, Any] = json.loads(source.read_text(encoding="utf-8"))
    return document


def _write(document: dict[str, Any], folder: Path, name: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text(json.dumps(document), encoding="utf-8")
    return path


def with_text_identifiers(folder: Path, source: Path = SOURCE_RUN) -> Path:
    """A copy of ``source`` whose ``tool serial`` and ``batch nr`` are text."""
    document = _document(source)
    document["tool serial"] = OTHER_SERIAL
    document["batch nr"] = OTHER_BATCH
    return _write(document, folder, f"text-ids_{source.name}")


def loosening_of(folder: Path, source: Path = SOURCE_RUN) -> Path:
    """A loosening with ``source``'s curve turned back (module docstring)."""
    document = _document(source)
    times: list[float] = []
    torques: list[float] = []
    angles: list[float] = []
    for step in document["tightening steps"]:
        graph = step["graph"]
        times += graph["time values"]
        torques += graph["torque values"]
        angles += graph["angle values"]
    first_s, last_s, end_deg = times[0], times[-1], angles[-1]
    graph = {
        "time values": [round(first_s + last_s - t, 4) for t in reversed(times)],
        "torque values": [round(-torque, 3) for torque in reversed(torques)],
        "angle values": [round(-(end_deg - angle), 2) for angle in reversed(angles)],
    }
    template = document["tightening steps"][1]  # the thread-forming step: its other fields
    step = copy.deepcopy(template)
    step.update(
        {
            "name": "Loosening",
            "last cmd": "TF Angle",
            "speed": LOOSENING_SPEED,
            "tightening functions": [
                {"name": "TF Angle", "nom": -1600, "act": graph["angle values"][-1]},
                {"name": "MFs TimeMax", "nom": 10, "act": round(last_s - first_s, 2)},
                {"name": "MFs TorqueMax", "nom": -3, "act": min(graph["torque values"])},
            ],
            "graph": graph,
        }
    )
    document.update(
        {
            "cycle": LOOSENING_RUN_ID,
            "prg nr": 9,
            "prg name": "Loosening",
            "last cmd": "TF Angle",
            "nominal torque": OTHER_NOMINAL_NM,
            "tool serial": OTHER_SERIAL,
            "batch nr": OTHER_BATCH,
            "tightening steps": [step],
        }
    )
    return _write(document, folder, f"Ch_{LOOSENING_RUN_ID:012d}.json")


def at_resolution(folder: Path, step_nm: float = 0.01, source: Path = SOURCE_RUN) -> Path:
    """A copy of ``source`` whose torque values are written to ``step_nm``."""
    document = _document(source)
    decimals = max(0, round(-math.log10(step_nm)))
    for step in document["tightening steps"]:
        graph = step["graph"]
        graph["torque values"] = [
            round(round(torque / step_nm) * step_nm, decimals) for torque in graph["torque values"]
        ]
    document["nominal torque"] = OTHER_NOMINAL_NM
    return _write(document, folder, f"resolution_{source.name}")
