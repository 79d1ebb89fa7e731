"""A result's trace from its recording, as the field values of IJT's ``JoiningTraceDataType``.

:func:`recorded_samples` reads a run's samples from the MCAP file the results
store names (``recording``); :func:`trace_values` (pure) gives the trace's
fields, which :mod:`.result_encoding` turns into asyncua's classes. The
samples are the recording's, one trace point each, none dropped, resampled
or averaged (a controller keeps 4096 points at most; a recording every one).

What goes where (OPC 40450-1, 10.6 to 10.9):

=========================  ===================================================
``TraceId``                ``<ResultId>/trace``; ``ResultId`` the result's
``StepTraces``             one ``StepTraceDataType`` over the whole run (a
                           recording is not cut at a controller's steps): its
                           ``StepTraceId`` ``<ResultId>/trace/run``, its
                           ``StepResultId`` the ResultId,
                           ``NumberOfTracePoints`` the samples,
                           ``SamplingInterval`` (ms) the median step between
                           samples on their own clock, ``StartTimeOffset`` 0
``StepTraceContent``       a ``TraceContentDataType`` per quantity, each with
                           ``NumberOfTracePoints`` values: ``Time`` (TIME 1,
                           ms since the first sample: a lost sample leaves a
                           gap there, not in the interval), ``Torque``
                           (TORQUE 2, N·m), ``Angle`` (ANGLE 3, degree),
                           ``Preload`` (FORCE 8, N; NaN where a sample has no
                           force, left out when none has)
=========================  ===================================================
"""

from __future__ import annotations

import itertools
import math
import statistics
from pathlib import Path
from typing import Any

from services.opcua.result_values import (
    DEGREE,
    MILLISECOND,
    NEWTON,
    NEWTON_METRE,
    QUANTITY_ANGLE,
    QUANTITY_FORCE,
    QUANTITY_TIME,
    QUANTITY_TORQUE,
)
from shared.recordings.mcap import RecordingScan, read_samples, run_times_s


def recorded_samples(recording: Path, station: str, run_id: int) -> list[dict[str, Any]]:
    """The samples of ``station``'s run ``run_id`` in ``recording``, in file order (the
    readable ones of a damaged file); InputError when the file cannot be read."""
    return [
        sample
        for sample in read_samples(RecordingScan(recording))
        if sample["run_id"] == run_id and sample["station"] == station
    ]


def trace_values(result_id: str, samples: list[dict[str, Any]]) -> dict[str, Any] | None:
    """The fields of a ``JoiningTraceDataType`` of ``samples``; None when there are none."""
    if not samples:
        return None
    times_ms = [time_s * 1000.0 for time_s in run_times_s(samples)]
    steps_ms = [later - earlier for earlier, later in itertools.pairwise(times_ms)]
    content: list[dict[str, Any]] = [
        _content("Time", times_ms, QUANTITY_TIME, MILLISECOND),
        _content("Torque", [s["torque_nm"] for s in samples], QUANTITY_TORQUE, NEWTON_METRE),
        _content("Angle", [s["angle_deg"] for s in samples], QUANTITY_ANGLE, DEGREE),
    ]
    forces_n = [s.get("force_n") for s in samples]
    if any(force is not None for force in forces_n):
        preload = [math.nan if force is None else force for force in forces_n]
        content.append(_content("Preload", preload, QUANTITY_FORCE, NEWTON))
    step: dict[str, Any] = {
        "StepTraceId": f"{result_id}/trace/run",
        "StepResultId": result_id,
        "NumberOfTracePoints": len(samples),
        "StartTimeOffset": 0.0,
        "StepTraceContent": content,
    }
    if steps_ms:
        step["SamplingInterval"] = statistics.median(steps_ms)
    return {"TraceId": f"{result_id}/trace", "ResultId": result_id, "StepTraces": [step]}


def _content(name: str, values: list[float], quantity: int, unit: Any) -> dict[str, Any]:
    return {
        "Name": name,
        "Values": [float(value) for value in values],
        "PhysicalQuantity": quantity,
        "EngineeringUnits": unit,
    }
