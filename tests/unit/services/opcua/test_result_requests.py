"""GetResultById: a result of a real results store (SQLite) with its steps, and its trace
from a real MCAP recording, encoded and decoded by asyncua with the loaded models.

Needs the fetched NodeSet2 files (``make opcua-nodesets``); skipped with the
reason without them.
"""

from __future__ import annotations

import asyncio
import math
from dataclasses import asdict
from pathlib import Path
from typing import Any

import pytest
from asyncua import Server, ua
from asyncua.ua.ua_binary import struct_from_binary, struct_to_binary

from services.opcua.nodeset_files import missing_files, nodeset_folder
from services.opcua.nodeset_loading import load_models
from services.opcua.result_encoding import model_class
from services.opcua.result_requests import ERROR_UNKNOWN_RESULT, result_by_id
from services.opcua.result_trace import trace_values
from services.opcua.result_values import MILLISECOND, QUANTITY_FORCE, QUANTITY_TIME
from shared.contract import ResultStep, encode
from shared.quality.cycle_result import cycle_result
from shared.recordings import classify
from shared.recordings.mcap import McapSink
from shared.results import ResultsStore, store_target, stored_result
from tests.support import factories

RUN = 3
SAMPLES = 40
LOST = 17  # the sample the bus lost

if missing_files(nodeset_folder()):
    pytest.skip(
        "the OPC UA models are not fetched (`make opcua-nodesets` needs npm)",
        allow_module_level=True,
    )


def _recording(folder: Path) -> Path:
    """Run 3's samples (torque 10 + n, angle n / 2, no force in sample 0, sample 17 lost)
    and run 4's, in one MCAP file."""
    with McapSink(folder / "st1_run3.mcap", {}, RUN, factories.T0) as sink:
        for run, count in ((RUN, SAMPLES), (RUN + 1, 5)):
            for n in range(count):
                if run == RUN and n == LOST:
                    continue
                sample = factories.sample(
                    run, n, torque_nm=10.0 + n, angle_deg=0.5 * n, force_n=None if n == 0 else n
                )
                sink.write(classify("boltwatch/st1/samples", encode(sample), sample.time_ns))
    return sink.path


def _store(folder: Path, recording: Path | None) -> Any:
    steps = (
        ResultStep("Tightening 1.1", "TF Torque", 20.0, 21.5, "OK"),
        ResultStep("Tightening 1.2", "", None, None, "NOK"),
    )
    target = store_target(folder, None)
    result = factories.result(RUN, steps=steps, source="controller")
    with ResultsStore(target) as store:
        store.add(
            [stored_result(result, "", None if recording is None else str(recording), "h", 1)]
        )
    return target


def _decoded(outputs: list[ua.Variant]) -> tuple[Any, int]:
    handle, result, error = (output.Value for output in outputs)
    assert handle == 0
    if result is None:
        return None, error
    cls = model_class("ResultDataType")
    return struct_from_binary(cls, ua.utils.Buffer(struct_to_binary(result))), error


@pytest.fixture(scope="module")
def models() -> None:
    """The models' classes (``ua.ResultDataType``...), loaded once for the module."""

    async def load() -> None:
        server = Server()
        await server.init()
        await load_models(server, nodeset_folder())

    asyncio.run(load())


def _asked(target: Any, identifier: str) -> tuple[Any, int]:
    return _decoded(result_by_id(target, "st1", identifier))


def test_a_result_asked_by_id_has_its_steps_and_every_recorded_sample_as_its_trace(
    tmp_path: Path, models: None
) -> None:
    target = _store(tmp_path, _recording(tmp_path))
    result, error = _asked(target, f"st1/{RUN}")
    assert error == 0
    [content] = result.ResultContent
    joining = content.Value
    first, second = joining.StepResults
    assert (first.StepResultId, first.Name, first.ResultEvaluation) == (
        f"st1/{RUN}/step/1",
        "Tightening 1.1",
        1,
    )
    [value] = first.StepResultValues
    assert (value.Name, value.MeasuredValue, value.TargetValue) == ("TF Torque", 21.5, 20.0)
    assert (second.ResultEvaluation, second.StepResultValues) == (2, None)

    trace = joining.Trace
    assert (trace.TraceId, trace.ResultId) == (f"st1/{RUN}/trace", f"st1/{RUN}")
    [step] = trace.StepTraces
    kept = [n for n in range(SAMPLES) if n != LOST]
    assert step.NumberOfTracePoints == len(kept)
    assert step.SamplingInterval == 1.0  # ms, the recording's 1 kHz
    time, torque, angle, preload = step.StepTraceContent
    assert time.PhysicalQuantity == QUANTITY_TIME
    assert time.EngineeringUnits.UnitId == MILLISECOND.unit_id
    assert time.Values == [float(n) for n in kept]  # the lost sample's gap is in the times
    assert torque.Values == [10.0 + n for n in kept]
    assert angle.Values == [0.5 * n for n in kept]
    assert preload.PhysicalQuantity == QUANTITY_FORCE
    assert math.isnan(preload.Values[0]) and preload.Values[1:] == [float(n) for n in kept[1:]]


def test_an_unknown_id_is_an_error_and_a_result_without_its_recording_says_why(
    tmp_path: Path, models: None
) -> None:
    target = _store(tmp_path, tmp_path / "gone.mcap")
    assert _asked(target, "st1/99") == (None, ERROR_UNKNOWN_RESULT)
    assert _asked(target, f"st2/{RUN}") == (None, ERROR_UNKNOWN_RESULT)
    result, error = _asked(target, f"st1/{RUN}")
    assert error == 0
    assert result.ResultContent[0].Value.Trace is None
    extended = {pair.Key: pair.Value.Value for pair in result.ResultMetaData.ExtendedMetaData}
    assert "gone.mcap: file not found" in extended["TraceMissing"]


def test_a_trace_of_one_sample_has_no_interval_and_none_of_no_samples() -> None:
    assert trace_values("st1/1", []) is None
    trace = trace_values("st1/1", [asdict(factories.sample(1, 0))])
    assert trace is not None
    [step] = trace["StepTraces"]
    assert step["NumberOfTracePoints"] == 1 and "SamplingInterval" not in step


def test_a_recording_still_written_gives_what_was_flushed(tmp_path: Path, models: None) -> None:
    final = tmp_path / "st1_run3_120000.mcap"
    with McapSink(final, {}, RUN, factories.T0, rename_when_complete=True) as sink:
        for n in range(SAMPLES):
            sample = factories.sample(RUN, n)
            sink.write(classify("boltwatch/st1/samples", encode(sample), sample.time_ns))
        sink.flush()
        assert not final.exists()  # under its writing name until complete
        result, error = _asked(_store(tmp_path, final), f"st1/{RUN}")
    assert error == 0
    [step] = result.ResultContent[0].Value.Trace.StepTraces
    assert step.NumberOfTracePoints == SAMPLES


def test_a_cycle_asked_by_id_is_its_sync_result_from_the_store(
    tmp_path: Path, models: None
) -> None:
    target = store_target(tmp_path, None)
    spindles = {
        n: factories.result(40 + n, spindle=n, sync_id=5, result=verdict, part_id="VIN-5")
        for n, verdict in ((1, "OK"), (2, "NOK"))
    }
    with ResultsStore(target) as store:
        store.add([stored_result(result, "", None, "h", 1) for result in spindles.values()])
        store.add_cycles([cycle_result("st1", 5, 3, spindles)], 2)  # spindle 3 never came
    result, error = _asked(target, "st1/cycle/5")
    assert error == 0
    meta = result.ResultMetaData
    assert (meta.ResultId, meta.Classification, meta.ResultEvaluation) == ("st1/cycle/5", 2, 2)
    assert meta.ResultEvaluationDetails.Text == "spindle 2 NOK; spindle 3 no result"
    assert meta.PartId == "VIN-5"
    assert [(c.CounterType, c.CounterValue) for c in meta.ResultCounters] == [(9, 3)]
    assert [
        (ref.Value.ResultMetaData.ResultId, ref.Value.ResultMetaData.ResultEvaluation)
        for ref in result.ResultContent
    ] == [("st1/41", 1), ("st1/42", 2)]
    assert _asked(target, "st1/cycle/6") == (None, ERROR_UNKNOWN_RESULT)
    assert _asked(target, "st2/cycle/5") == (None, ERROR_UNKNOWN_RESULT)  # another station's
