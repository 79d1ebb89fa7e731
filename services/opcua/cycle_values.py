"""A multi-spindle cycle's common result as the field values of an IJT sync result, pure.

OPC 40450-1 models a synchronised multi-spindle process as a combined result whose
``JoiningResultMetaDataType.Classification`` is SYNC_RESULT (2), sent the way Annex F
recommends (option 1, "a result with references to sub-results"): each spindle's
result is sent on its own as soon as it is known (a SINGLE_RESULT, its spindle number
in its ``ResultCounters``: :func:`.result_values.spindle_counters`), and the cycle's
result refers to them: its ``ResultContent`` holds, per spindle whose result came, a
``ResultDataType`` whose ``ResultMetaData`` carries only the sub-result's ``ResultId``,
``Classification`` SINGLE_RESULT, its ``ResultEvaluation`` and its spindle number, and
an empty ``ResultContent`` (Annex F.6's layout).

What goes where (:class:`~shared.contract.CycleResult`):

==============================  ==================================================
CycleResult                     IJT field
==============================  ==================================================
``station``/``sync_id``         ``ResultId`` ``"<station>/cycle/<sync id>"`` (never
                                a tightening's: a run's id has no ``/``)
``sync_id``                     ``SequenceNumber`` (the controller's counter of
                                cycles; Annex F.6 lets a combined result take one)
``time_ns``                     ``CreationTime`` (its last spindle's end)
``part_id``, ``program_id``     ``PartId``, ``InternalRecipeId``
``result``, ``nok_reasons``     ``ResultEvaluation`` (OK 1 only when every spindle
                                is OK, NotOK 2), ``ResultEvaluationDetails``
                                ("spindle 2 NOK (...); spindle 4 no result")
``spindles``                    ``ResultCounters``: TOTAL_NUMBER_OF_SPINDLES (9);
                                ``ResultContent``: a reference per spindle's run
                                (a spindle with no result has none: the details
                                say it)
``station``, ``sync_id``,       ``ExtendedMetaData`` (key, text)
``source``
==============================  ==================================================
"""

from __future__ import annotations

from typing import Any

from services.opcua.result_values import (
    CLASSIFICATION_SINGLE,
    EVALUATION_NOT_OK,
    EVALUATION_OK,
    JOINING_TECHNOLOGY,
    RESULT_STATE_COMPLETED,
    parse_id,
    result_id,
    spindle_counters,
    utc_time,
)
from shared.contract import CycleResult

#: JoiningResultMetaDataType.Classification: a group of results of a synchronised process
CLASSIFICATION_SYNC = 2
#: ResultCounterDataType.CounterType (OPC 40450-1, 10.11): how many spindles the system has
COUNTER_TOTAL_NUMBER_OF_SPINDLES = 9


def cycle_result_id(station: str, sync_id: int) -> str:
    """The ResultId of a station's cycle (no tightening's: see :func:`.result_values.result_id`)."""
    return f"{station}/cycle/{sync_id}"


def parse_cycle_result_id(text: str) -> tuple[str, int] | None:
    """The station and sync id of the ResultId ``text`` (what :func:`cycle_result_id`
    gives); None for a text it never gives."""
    station, _, sync = text.rpartition("/cycle/")
    sync_id = parse_id(sync)
    return None if not station or sync_id is None else (station, sync_id)


def _evaluation(verdict: str | None) -> int:
    return EVALUATION_OK if verdict == "OK" else EVALUATION_NOT_OK


def cycle_values(cycle: CycleResult) -> dict[str, Any]:
    """``{"ResultMetaData": {...}, "ResultContent": [<a spindle's reference>, ...]}``."""
    meta: dict[str, Any] = {
        "ResultId": cycle_result_id(cycle.station, cycle.sync_id),
        "CreationTime": utc_time(cycle.time_ns),
        "InternalRecipeId": str(cycle.program_id),
        "ResultState": RESULT_STATE_COMPLETED,
        "ResultEvaluation": _evaluation(cycle.result),
        "JoiningTechnology": JOINING_TECHNOLOGY,
        "SequenceNumber": cycle.sync_id,
        "Classification": CLASSIFICATION_SYNC,
        "ResultCounters": [
            {
                "Name": "Spindles",
                "CounterValue": len(cycle.spindles),
                "CounterType": COUNTER_TOTAL_NUMBER_OF_SPINDLES,
            }
        ],
        "ExtendedMetaData": {
            "Station": cycle.station,
            "SyncId": str(cycle.sync_id),
            "Source": cycle.source,
        },
    }
    if cycle.part_id is not None:
        meta["PartId"] = cycle.part_id
    if cycle.nok_reasons:
        meta["ResultEvaluationDetails"] = cycle.nok_reasons
    references = [
        {
            "ResultMetaData": {
                "ResultId": result_id(cycle.station, spindle.run_id),
                "ResultEvaluation": _evaluation(spindle.result),
                "Classification": CLASSIFICATION_SINGLE,
                "ResultCounters": spindle_counters(spindle.spindle),
            },
            "ResultContent": [],
        }
        for spindle in cycle.spindles
        if spindle.run_id is not None
    ]
    return {"ResultMetaData": meta, "ResultContent": references}
