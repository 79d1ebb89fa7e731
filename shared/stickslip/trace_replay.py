"""Run the predictor core over a whole offline trace (``boltwatch predict``, benchmarks).

The same :class:`~shared.stickslip.PredictorCore` as the live service,
sample by sample; the outputs become JSON-ready dicts (the
``boltwatch predict`` contract in docs/design.md).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator
from typing import Any

from shared.contract import Trace
from shared.stickslip.event_figures import EventFigures
from shared.stickslip.outputs import CoreDecision
from shared.stickslip.predictor_core import CoreOutput, PredictorCore


def replay(core: PredictorCore, trace: Trace) -> Iterator[CoreOutput]:
    """Feed every sample of ``trace`` to ``core``; yield the outputs in order."""
    columns = zip(
        trace.time_s.tolist(),
        trace.torque_nm.tolist(),
        trace.force_n.tolist(),
        trace.angle_deg.tolist(),
        strict=True,
    )
    update = core.update
    for time_s, torque_nm, force_n, angle_deg in columns:
        outputs = update(time_s, torque_nm, force_n, angle_deg)
        if outputs:
            yield from outputs


def output_record(output: CoreOutput) -> dict[str, Any]:
    """The JSON Lines object of one output: ``{"type": "event"|"stop"|"stage", "time_s": ...}``
    (``stage``: a final stage's command, only from a core whose settings have one)."""
    fields = dataclasses.asdict(output)
    if isinstance(output, EventFigures):
        record: dict[str, Any] = {"type": "event"}
    elif isinstance(output, CoreDecision):
        record = {"type": "stop"}
    else:
        record = {"type": "stage"}
    record.update(fields)
    return json_safe(record)


def json_safe(value: Any) -> Any:
    """NaN and infinities become null, in nested dicts and lists too: JSON has no such numbers."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {key: json_safe(item) for key, item in value.items()}
    if isinstance(value, list):
        return [json_safe(item) for item in value]
    return value
