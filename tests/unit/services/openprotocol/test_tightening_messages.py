"""A controller's tightening goes out as a CAN station's run: the same messages, the same order."""

from __future__ import annotations

import math

from services.openprotocol.controller_tightening import Curve, Tightening
from services.openprotocol.tightening_messages import tightening_messages
from shared.contract import (
    ControllerResult,
    Intensity,
    RunSummary,
    Sample,
    StickSlipEvent,
    StopDecision,
    TighteningResult,
    ToolState,
)
from tests.support.bridge_harness import figures

START_NS = 1_700_000_000_000_000_000


def saw_tooth(samples: int) -> tuple[float, ...]:
    """A torque ramp to about 200 Nm with stick-slip drops (a predictor sees events)."""
    values = []
    for index in range(samples):
        ramp = 210.0 * index / samples
        values.append(ramp - (8.0 if index % 60 > 50 else 0.0) * ramp / 200.0)
    return tuple(values)


def test_the_messages_of_a_tightening_in_the_order_of_a_can_station() -> None:
    torque = Curve(7, "torque", START_NS, 0.001, saw_tooth(1200))
    angle = Curve(7, "angle", START_NS, 0.001, tuple(0.05 * i for i in range(1100)))
    tightening = Tightening(figures(7), torque, angle)
    messages = tightening_messages("st1", 3, 1007, tightening, "program one")
    kinds = [type(message) for message in messages]
    assert kinds[0] is ToolState and messages[0].state == "running"
    samples = [m for m in messages if isinstance(m, Sample)]
    assert len(samples) == 1200
    assert samples[5].time_ns == START_NS + 5_000_000 and samples[5].time_s == 0.005
    assert math.isnan(samples[1150].angle_deg), "a shorter angle curve is never shifted"
    assert all(s.run_id == 1007 and s.force_n is None for s in samples)
    tail = kinds[-4:]
    assert tail == [ToolState, ControllerResult, TighteningResult, RunSummary]
    done = messages[-4]
    assert done.state == "done" and done.time_ns == samples[-1].time_ns + 1
    outputs = [m for m in messages if isinstance(m, StickSlipEvent | Intensity | StopDecision)]
    assert any(isinstance(m, StickSlipEvent) for m in outputs)
    assert all(m.advisory for m in outputs if isinstance(m, StopDecision))
    result = messages[-2]
    assert result.source == "controller" and result.result == "OK"
    assert result.tightening_id == 7 and result.run_id == 1007 and result.tool_id == 3
    assert result.final_torque_nm.min == 180.0 and result.final_torque_nm.status == "ok"
    assert result.part_id == "VIN1" and result.batch_counter == 3
    assert result.program_name == "program one"
    summary = messages[-1]
    assert summary.stop_reason is None and summary.samples == 1200
    assert summary.reached_torque_nm == 200.0 and summary.target_torque_nm == 200.0


def test_a_result_without_curves_is_a_run_without_samples_and_keeps_its_verdict() -> None:
    nok = figures(8)
    nok = type(nok)(**{**{f: getattr(nok, f) for f in nok.__slots__}, "ok": False})
    messages = tightening_messages("st1", 3, 8, Tightening(nok, None, None))
    assert [type(m) for m in messages] == [
        ToolState,
        ToolState,
        ControllerResult,
        TighteningResult,
        RunSummary,
    ]
    assert messages[0].time_ns == nok.time_ns
    result = messages[3]
    assert result.result == "NOK" and "NOK" in result.nok_reasons
    assert messages[4].samples == 0 and messages[4].events == 0
