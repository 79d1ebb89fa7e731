"""A multi-spindle cycle's common result as an IJT sync result (pure: no asyncua)."""

from __future__ import annotations

from services.opcua.cycle_values import cycle_result_id, cycle_values
from services.opcua.result_values import parse_result_id, result_id, utc_time
from shared.quality.cycle_result import cycle_result
from tests.support import factories


def _spindle(run_id: int, spindle: int, **changes: object) -> object:
    return factories.result(run_id, spindle=spindle, sync_id=5, part_id="VIN-5", **changes)


def test_a_cycle_is_a_sync_result_referring_to_each_spindle_s_result() -> None:
    results = {1: _spindle(11, 1), 2: _spindle(12, 2, time_ns=factories.T0 + 7_000)}
    values = cycle_values(cycle_result("st1", 5, 2, results))  # type: ignore[arg-type]
    meta = values["ResultMetaData"]
    assert meta["ResultId"] == "st1/cycle/5" == cycle_result_id("st1", 5)
    assert meta["Classification"] == 2  # SYNC_RESULT
    assert meta["ResultEvaluation"] == 1  # OK: every spindle is
    assert "ResultEvaluationDetails" not in meta
    assert meta["SequenceNumber"] == 5
    assert meta["PartId"] == "VIN-5"
    assert meta["CreationTime"] == utc_time(factories.T0 + 7_000)  # its last spindle's end
    assert meta["ResultCounters"] == [
        {"Name": "Spindles", "CounterValue": 2, "CounterType": 9}  # TOTAL_NUMBER_OF_SPINDLES
    ]
    assert [ref["ResultMetaData"] for ref in values["ResultContent"]] == [
        {
            "ResultId": result_id("st1", run_id),
            "ResultEvaluation": 1,
            "Classification": 1,  # SINGLE_RESULT
            "ResultCounters": [{"Name": "Spindle", "CounterValue": spindle, "CounterType": 7}],
        }
        for run_id, spindle in ((11, 1), (12, 2))
    ]
    assert [ref["ResultContent"] for ref in values["ResultContent"]] == [[], []]  # references
    # never a tightening's ResultId (st1's run 5 is "st1/5"; no station is named "st1/cycle")
    assert parse_result_id(meta["ResultId"]) == ("st1/cycle", 5)


def test_a_cycle_with_a_nok_spindle_and_a_missing_one_is_nok_and_says_why() -> None:
    results = {1: _spindle(21, 1), 2: _spindle(22, 2, result="NOK", nok_reasons="torque high")}
    values = cycle_values(cycle_result("st1", 5, 3, results))  # type: ignore[arg-type]
    meta = values["ResultMetaData"]
    assert meta["ResultEvaluation"] == 2  # NotOK
    assert meta["ResultEvaluationDetails"] == "spindle 2 NOK (torque high); spindle 3 no result"
    assert meta["ResultCounters"][0]["CounterValue"] == 3
    references = [ref["ResultMetaData"] for ref in values["ResultContent"]]
    assert [(r["ResultId"], r["ResultEvaluation"]) for r in references] == [
        ("st1/21", 1),
        ("st1/22", 2),
    ]  # spindle 3 has no result to refer to
