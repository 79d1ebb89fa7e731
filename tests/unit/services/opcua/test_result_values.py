"""A TighteningResult as IJT field values (pure: no asyncua)."""

from __future__ import annotations

from datetime import UTC, datetime, timedelta

from services.opcua.result_values import (
    DEGREE,
    NEWTON,
    NEWTON_METRE,
    parse_result_id,
    result_id,
    result_values,
    utc_time,
)
from shared.contract import INT64_MAX, JudgedFigure
from tests.support import factories


def test_a_result_gives_its_metadata_and_its_three_figures_with_units() -> None:
    result = factories.result(41, part_id="VIN-1", program_name="M14")
    values = result_values(result)
    meta = values["ResultMetaData"]
    assert meta["ResultId"] == "st1/41" == result_id("st1", 41)
    assert meta["PartId"] == "VIN-1"
    assert meta["InternalRecipeId"] == "1"
    assert meta["Name"] == "M14"
    assert meta["SequenceNumber"] == 41
    assert meta["Classification"] == 1
    assert meta["ResultEvaluation"] == 1
    assert meta["CreationTime"] == datetime.fromtimestamp(result.time_ns / 1e9, tz=UTC)
    assert meta["ExtendedMetaData"]["StopReason"] == "plateau_closest"
    [content] = values["ResultContent"]
    by_name = {value["Name"]: value for value in content["OverallResultValues"]}
    assert by_name["Torque"]["MeasuredValue"] == 190.0
    assert by_name["Torque"]["LowLimit"] == 180.0
    assert by_name["Torque"]["EngineeringUnits"] is NEWTON_METRE
    assert by_name["Angle"]["EngineeringUnits"] is DEGREE
    assert by_name["Preload"]["EngineeringUnits"] is NEWTON
    assert by_name["StickSlipEvents"]["MeasuredValue"] == 9.0
    assert by_name["ProcessIntensity"]["MeasuredValue"] == 0.4


def test_a_figure_not_measured_is_left_out_and_a_nok_says_why() -> None:
    result = factories.result(
        2,
        final_force_n=JudgedFigure(None, None, None, "not_judged"),
        final_torque_nm=JudgedFigure(250.0, 180.0, 240.0, "high"),
        result="NOK",
        nok_reasons="torque high",
        events=None,
        process_intensity=None,
        stop_reason=None,
    )
    values = result_values(result)
    meta = values["ResultMetaData"]
    assert meta["ResultEvaluation"] == 2
    assert meta["ResultEvaluationDetails"] == "torque high"
    assert "PartId" not in meta
    assert meta["ExtendedMetaData"]["StopReason"] == "tool"
    names = [value["Name"] for value in values["ResultContent"][0]["OverallResultValues"]]
    assert names == ["Torque", "Angle"]
    assert values["ResultContent"][0]["OverallResultValues"][0]["ResultEvaluation"] == 2


def test_unit_ids_are_the_unece_codes_of_opc_10000_8() -> None:
    assert NEWTON_METRE.unit_id == 20053  # "NU"
    assert DEGREE.unit_id == 17476  # "DD"
    assert NEWTON.unit_id == 5129559  # "NEW"


def test_a_creation_time_is_the_end_s_whole_microseconds_exactly() -> None:
    """1 999 ns past a whole second is 1 µs (a float of the seconds since 1970 made it 2)."""
    second = datetime.fromtimestamp(factories.T0 // 1_000_000_000, tz=UTC)
    assert utc_time(factories.T0 + 1_999) == second + timedelta(microseconds=1)


def test_a_result_id_reads_back_and_no_other_text_is_one() -> None:
    assert parse_result_id(result_id("line 2/st1", 0)) == ("line 2/st1", 0)
    assert parse_result_id(result_id("st1", INT64_MAX)) == ("st1", INT64_MAX)
    for text in ("st1/--5", "st1/²", "st1/٣", "st1/-5", "st1/+5", "st1/05", "st1/", "/5", "5"):
        assert parse_result_id(text) is None, text
    assert parse_result_id(f"st1/{INT64_MAX + 1}") is None
    assert parse_result_id("st1/" + "1" * 5000) is None  # more digits than int() reads


def test_a_spindle_s_result_names_its_spindle_and_a_single_spindle_s_has_no_counters() -> None:
    spindle = result_values(factories.result(42, spindle=3, sync_id=17))["ResultMetaData"]
    assert spindle["ResultCounters"] == [
        {"Name": "Spindle", "CounterValue": 3, "CounterType": 7}  # SPINDLE_NUMBER
    ]
    assert spindle["ExtendedMetaData"]["SyncId"] == "17"
    assert spindle["Classification"] == 1  # a spindle's result is a single result
    single = result_values(factories.result(42))["ResultMetaData"]
    assert "ResultCounters" not in single
    assert "SyncId" not in single["ExtendedMetaData"]
