"""``boltwatch import CONTROLLER.json... --out-dir DIR``: controller runs to offline traces.

Reads the JSON runs a Bosch Rexroth CS351 controller exports (one file per
run) and writes one trace CSV per run (header ``time_s,torque_nm,angle_deg,
force_n``, force empty: the controller has no preload channel). The
``graph`` of each entry of ``tightening steps`` is concatenated in order,
keeping the controller's own timing, repeated timestamps and gaps
untouched, so the predictor sees the data as it was recorded.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

NAME = "import"
HELP = "convert tightening-controller JSON runs (CS351) into trace CSVs for boltwatch predict"

STEPS_KEY = "tightening steps"
GRAPH_KEYS = ("time values", "torque values", "angle values")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("runs", type=Path, nargs="+", metavar="CONTROLLER.json", help="run files")
    parser.add_argument(
        "--out-dir", type=Path, required=True, metavar="DIR", help="folder for the CSV traces"
    )


def run(args: argparse.Namespace) -> int:
    from shared.trace import write_trace

    args.out_dir.mkdir(parents=True, exist_ok=True)
    for path in args.runs:
        rows = controller_rows(path)
        target = args.out_dir / f"{path.stem}.csv"
        count = write_trace(target, rows)
        print(f"{path} -> {target} ({count} samples)")
    return 0


def controller_rows(path: Path) -> list[tuple[float, float, float, float | None]]:
    """The trace rows of one controller JSON run; InputError naming the file if unusable."""
    import json

    from shared.errors import InputError

    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError as err:
        raise InputError(f"{path}: file not found") from err
    except UnicodeDecodeError as err:
        raise InputError(f"{path}: not a text file ({err.reason})") from err
    except json.JSONDecodeError as err:
        raise InputError(
            f"{path}: line {err.lineno}: not valid JSON (truncated or corrupt?): {err.msg}"
        ) from err
    except OSError as err:
        raise InputError(f"{path}: cannot be read: {err.strerror}") from err
    steps = document.get(STEPS_KEY) if isinstance(document, dict) else None
    if not isinstance(steps, list) or not steps:
        raise InputError(f"{path}: no '{STEPS_KEY}' list: not a CS351 controller run")
    rows: list[tuple[float, float, float, float | None]] = []
    for number, step in enumerate(steps):
        rows.extend(_step_rows(path, number, step))
    if not rows:
        raise InputError(f"{path}: the tightening steps hold no samples")
    return rows


def _step_rows(
    path: Path, number: int, step: Any
) -> list[tuple[float, float, float, float | None]]:
    from shared.errors import InputError

    where = f"{path}: {STEPS_KEY}[{number}]"
    graph = step.get("graph") if isinstance(step, dict) else None
    if not isinstance(graph, dict):
        raise InputError(f"{where}: no 'graph'")
    columns = []
    for key in GRAPH_KEYS:
        values = graph.get(key)
        if not isinstance(values, list):
            raise InputError(f"{where}.graph: no '{key}' list")
        if not all(isinstance(v, int | float) and not isinstance(v, bool) for v in values):
            raise InputError(f"{where}.graph: '{key}' holds a value that is not a number")
        columns.append(values)
    lengths = {len(column) for column in columns}
    if len(lengths) != 1:
        raise InputError(f"{where}.graph: time, torque and angle lists differ in length")
    return [(float(t), float(tq), float(a), None) for t, tq, a in zip(*columns, strict=True)]
