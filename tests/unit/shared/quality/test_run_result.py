"""A live run's TighteningResult, its summary judged against its program's windows."""

from __future__ import annotations

import json
import math
from typing import Any

import pytest

from shared.config import Program
from shared.contract import RunSummary, TighteningResult, decode, encode
from shared.quality import tightening_result
from tests.support import factories

WINDOWS = {
    "torque_min_nm": 180.0,
    "torque_max_nm": 220.0,
    "angle_min_deg": 40.0,
    "angle_max_deg": 80.0,
    "force_min_n": 53000.0,
    "force_max_n": 59000.0,
}


def program(**windows: float) -> Program:
    return factories.program(name="M14 to 56 kN", **windows)


def summary(**changes: Any) -> RunSummary:
    """The run these tests judge: a simulated run of program 1 (README's table)."""
    run: dict[str, Any] = {
        "tool_id": 7,
        "program_id": 1,
        "reached_force_n": 56100.0,
        "reached_torque_nm": 201.5,
        "reached_angle_deg": 61.0,
        "error_pct": 0.18,
        "events": 41,
        "stop_reason": "plateau_closest",
        "process_intensity": 1.03e6,
        "samples": 1677,
        "started_ns": 1_700_000_000_000_000_000,
        "ended_ns": 1_700_000_001_700_000_000,
    }
    return factories.summary(1795272477, **{**run, **changes})


def test_a_run_in_every_window_is_ok_with_its_figures_windows_and_run() -> None:
    result = tightening_result(summary(), program(**WINDOWS))
    assert result.result == "OK" and result.nok_reasons == ""
    assert (result.final_torque_nm.value, result.final_torque_nm.status) == (201.5, "ok")
    assert (result.final_torque_nm.min, result.final_torque_nm.max) == (180.0, 220.0)
    assert (result.final_angle_deg.value, result.final_angle_deg.status) == (61.0, "ok")
    assert (result.final_force_n.value, result.final_force_n.status) == (56100.0, "ok")
    assert (result.tightening_id, result.run_id, result.tool_id) == (1795272477, 1795272477, 7)
    assert (result.program_id, result.program_name) == (1, "M14 to 56 kN")
    assert (result.part_id, result.batch_counter, result.steps) == (None, None, [])
    assert (result.events, result.process_intensity) == (41, 1.03e6)
    assert (result.stop_reason, result.source) == ("plateau_closest", "predictor")
    assert result.time_ns == summary().ended_ns


@pytest.mark.parametrize(
    ("changes", "figure", "status", "reason"),
    [
        ({"reached_torque_nm": 179.9}, "final_torque_nm", "low", "torque low: 179.9 Nm"),
        ({"reached_torque_nm": 220.1}, "final_torque_nm", "high", "torque high: 220.1 Nm"),
        ({"reached_angle_deg": 39.0}, "final_angle_deg", "low", "angle low: 39 deg"),
        ({"reached_angle_deg": 81.0}, "final_angle_deg", "high", "angle high: 81 deg"),
        ({"reached_force_n": 52999.0}, "final_force_n", "low", "preload low: 52999 N"),
        ({"reached_force_n": 59001.0}, "final_force_n", "high", "preload high: 59001 N"),
    ],
)
def test_a_figure_out_of_its_window_is_low_or_high_and_the_run_nok(
    changes: dict[str, float], figure: str, status: str, reason: str
) -> None:
    result = tightening_result(summary(**changes), program(**WINDOWS))
    assert getattr(result, figure).status == status
    assert result.result == "NOK"
    assert result.nok_reasons.startswith(reason) and ";" not in result.nok_reasons


def test_the_bounds_themselves_are_ok() -> None:
    at_bounds = summary(reached_torque_nm=180.0, reached_angle_deg=80.0, reached_force_n=59000.0)
    assert tightening_result(at_bounds, program(**WINDOWS)).result == "OK"


def test_without_windows_nothing_is_judged_and_a_good_run_is_ok() -> None:
    result = tightening_result(summary(reached_torque_nm=9.0), program())
    for figure in (result.final_torque_nm, result.final_angle_deg, result.final_force_n):
        assert figure.status == "not_judged" and figure.min is None and figure.max is None
    assert result.final_torque_nm.value == 9.0
    assert result.result == "OK"


def test_one_bound_judges_one_side() -> None:
    only_max = program(torque_max_nm=220.0)
    assert tightening_result(summary(reached_torque_nm=5.0), only_max).result == "OK"
    high = tightening_result(summary(reached_torque_nm=230.0), only_max)
    assert high.final_torque_nm.status == "high"
    assert high.nok_reasons == "torque high: 230 Nm, at most 220 Nm"


@pytest.mark.parametrize(
    ("changes", "reason"),
    [
        ({"tool_state": "aborted"}, "the tool aborted the run"),
        ({"stop_reason": "torque_limit"}, "stopped on torque_limit"),
        ({"stop_reason": "input_fault"}, "stopped on input_fault"),
    ],
)
def test_an_aborted_run_or_a_fault_stop_is_nok_even_without_windows(
    changes: dict[str, Any], reason: str
) -> None:
    result = tightening_result(summary(**changes), program())
    assert result.result == "NOK" and result.nok_reasons == reason


def test_a_tool_that_stopped_itself_or_a_late_decision_is_judged_by_its_figures() -> None:
    by_itself = summary(stop_reason=None, late_decision="plateau_closest")
    assert tightening_result(by_itself, program(**WINDOWS)).result == "OK"


def test_a_window_with_no_measured_value_is_nok_and_the_result_holds_no_nan() -> None:
    lost = summary(reached_force_n=None, reached_angle_deg=None, reached_torque_nm=math.nan)
    result = tightening_result(lost, program(**WINDOWS))
    assert result.result == "NOK"
    assert result.nok_reasons == (
        "torque not measured, window 180 to 220 Nm; "
        "angle not measured, window 40 to 80 deg; "
        "preload not measured, window 53000 to 59000 N"
    )
    for figure in (result.final_torque_nm, result.final_angle_deg, result.final_force_n):
        assert figure.value is None and figure.status == "not_judged"
    payload = encode(result)
    assert b"NaN" not in payload and b"Infinity" not in payload
    assert decode(TighteningResult, payload) == result
    json.loads(payload)  # standard JSON


def test_the_result_names_the_part_it_is_given_and_none_without() -> None:
    """The part is the caller's (the line scanned it before the run): passed in, kept as is."""
    assert tightening_result(summary(), program(**WINDOWS)).part_id is None
    result = tightening_result(summary(), program(**WINDOWS), "WVWZZZ1JZXW000001")
    assert result.part_id == "WVWZZZ1JZXW000001"
    assert decode(TighteningResult, encode(result)) == result
    assert (result.result, result.batch_counter) == ("OK", None)
