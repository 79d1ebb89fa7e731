"""A tightening in the words of Open Protocol: 0061, 0065 and its 0900 curves. Pure.

- 0061 (:func:`last_result`) at revision 1 or 2 and 0065 (:func:`old_result`)
  at revision 1 or 2 carry the controller's result
  (:class:`~services.rig.openprotocol.tightening.Tightening`): pset = the
  program id, job 0, torques in Nm (hundredths on the wire), angles in whole
  degrees (rounded), the time stamp in the controller's time zone; revision 2
  adds the strategy (2: torque control / angle monitoring: the simulated
  controller always judges both), the tool serial, the error status (1 when
  the run aborted on a hard limit, else 0), and zeros for what the simulated
  tool does not have (rundown angle, current monitoring, self-tap,
  prevailing torque: status OK, values 0).
- 0900 (:func:`trace_curves`): one curve per trace type asked (angle 1,
  torque 2), the run's samples at 1 ms, time stamp = the run's start (whole
  seconds, as every Open Protocol time stamp). Samples are 16-bit integers
  times a coefficient: the smallest of 0.001, 0.002, 0.005, 0.01, ... that
  holds the curve's largest value (0.01 Nm, 0.01 deg for the paper's joint).
  One 0900 holds at most 9999 bytes (:data:`MAX_TRACE_SAMPLES` samples): a
  longer run (more than 4.8 s) is sent every k-th sample, time step k ms,
  rather than in linked messages (which the codec does not join).
"""

from __future__ import annotations

import dataclasses
import datetime as dt
import math
from typing import Any

import numpy as np
import numpy.typing as npt

from services.rig.openprotocol.tightening import SAMPLE_PERIOD_S, FigureStatus, Tightening
from shared.openprotocol import (
    UNIT_DEGREE,
    UNIT_NM,
    BatchStatus,
    LastTighteningResult,
    OldTighteningResult,
    TraceCurve,
    TraceType,
    ValueStatus,
    format_timestamp,
)

STRATEGY_TORQUE_ANGLE_MONITORING = 2
#: samples that fit one 0900 (9999 bytes: header, about 120 of ASCII, 2 bytes a sample)
MAX_TRACE_SAMPLES = 4800
#: the largest raw value of a 16-bit sample used (a margin below 32767)
RAW_MAX = 32000

_VALUE_STATUS: dict[FigureStatus, ValueStatus] = {
    "low": ValueStatus.LOW,
    "ok": ValueStatus.OK,
    "high": ValueStatus.HIGH,
}
_BATCH_STATUS = {"nok": BatchStatus.NOK, "ok": BatchStatus.OK, "not_used": BatchStatus.NOT_USED}


class ControllerIdentity:
    """Who the controller says it is in its messages."""

    def __init__(self, station_id: str, tool_id: int, timezone: dt.tzinfo) -> None:
        self.cell_id = 1
        self.channel_id = 1
        self.controller_name = f"boltwatch sim {station_id}"[:25]
        self.tool_serial = f"SIM-{tool_id}"
        self.controller_serial = f"SIMC-{tool_id}"[:10]
        self.timezone = timezone

    def timestamp(self, time_ns: int) -> str:
        return format_timestamp(time_ns, self.timezone)


def last_result(
    tightening: Tightening, revision: int, identity: ControllerIdentity
) -> LastTighteningResult:
    """The 0061 of ``tightening`` at ``revision`` (1 or 2)."""
    result = LastTighteningResult(
        cell_id=identity.cell_id,
        channel_id=tightening.channel_id,
        controller_name=identity.controller_name,
        vin=tightening.vin,
        job_id=0,
        pset_id=tightening.program_id,
        batch_size=tightening.batch_size,
        batch_counter=tightening.batch_counter,
        tightening_ok=tightening.ok,
        batch_status=_BATCH_STATUS[tightening.batch_status],
        torque_status=_VALUE_STATUS[tightening.torque_status],
        angle_status=_VALUE_STATUS[tightening.angle_status],
        torque_min_nm=tightening.torque_min_nm,
        torque_max_nm=tightening.torque_max_nm,
        torque_final_target_nm=tightening.torque_target_nm,
        torque_nm=tightening.final_torque_nm,
        angle_min_deg=round(tightening.angle_min_deg),
        angle_max_deg=round(tightening.angle_max_deg),
        angle_final_target_deg=round(tightening.angle_target_deg),
        angle_deg=round(tightening.final_angle_deg),
        tightening_id=tightening.tightening_id,
        timestamp=identity.timestamp(tightening.ended_ns),
        pset_changed=identity.timestamp(tightening.ended_ns),
        revision=revision,
    )
    if revision < 2:
        return result
    return dataclasses.replace(result, **_second_revision(tightening, identity, limits=True))


def old_result(
    tightening: Tightening, revision: int, identity: ControllerIdentity
) -> OldTighteningResult:
    """The 0065 of ``tightening`` at ``revision`` (1 or 2)."""
    result = OldTighteningResult(
        tightening_id=tightening.tightening_id,
        vin=tightening.vin,
        pset_id=tightening.program_id,
        batch_counter=tightening.batch_counter,
        tightening_ok=tightening.ok,
        batch_status=_BATCH_STATUS[tightening.batch_status],
        torque_status=_VALUE_STATUS[tightening.torque_status],
        angle_status=_VALUE_STATUS[tightening.angle_status],
        torque_nm=tightening.final_torque_nm,
        angle_deg=round(tightening.final_angle_deg),
        timestamp=identity.timestamp(tightening.ended_ns),
        revision=revision,
    )
    if revision < 2:
        return result
    second = _second_revision(tightening, identity, limits=False)
    return dataclasses.replace(result, job_id=0, batch_size=tightening.batch_size, **second)


def _second_revision(
    tightening: Tightening, identity: ControllerIdentity, *, limits: bool
) -> dict[str, Any]:
    """The revision 2 fields of 0061 (``limits``: with the windows of what is not
    measured) or 0065: what the simulated tool does not have is OK and 0."""
    fields: dict[str, Any] = {
        "strategy": STRATEGY_TORQUE_ANGLE_MONITORING,
        "strategy_options": 0,
        "rundown_angle_status": ValueStatus.OK,
        "current_monitoring_status": ValueStatus.OK,
        "selftap_status": ValueStatus.OK,
        "prevail_torque_monitoring_status": ValueStatus.OK,
        "prevail_torque_compensate_status": ValueStatus.OK,
        "tightening_error_status": 1 if tightening.curves.aborted else 0,
        "rundown_angle_deg": 0,
        "current_monitoring_pct": 0,
        "selftap_torque_nm": 0.0,
        "prevail_torque_nm": 0.0,
        "job_sequence_number": 0,
        "sync_tightening_id": tightening.sync_tightening_id,
        "tool_serial": identity.tool_serial,
    }
    if limits:
        fields |= {
            "rundown_angle_min_deg": 0,
            "rundown_angle_max_deg": 0,
            "current_monitoring_min_pct": 0,
            "current_monitoring_max_pct": 0,
            "selftap_min_nm": 0.0,
            "selftap_max_nm": 0.0,
            "prevail_torque_min_nm": 0.0,
            "prevail_torque_max_nm": 0.0,
        }
    return fields


def trace_curves(
    tightening: Tightening, trace_types: tuple[int, ...], identity: ControllerIdentity
) -> list[TraceCurve]:
    """The 0900 curves of ``tightening``, one per trace type asked that the tool has."""
    curves = tightening.curves
    step = math.ceil(len(curves.torque_nm) / MAX_TRACE_SAMPLES)
    timestamp = identity.timestamp(tightening.started_ns)
    by_type = {
        TraceType.ANGLE: (curves.angle_deg, UNIT_DEGREE),
        TraceType.TORQUE: (curves.torque_nm, UNIT_NM),
    }
    messages = []
    for trace_type in trace_types:
        values, unit = by_type[TraceType(trace_type)]
        kept = values[::step]
        messages.append(
            TraceCurve.build(
                result_id=tightening.tightening_id,
                timestamp=timestamp,
                trace_type=trace_type,
                unit=unit,
                samples=tuple(kept.tolist()),
                time_step_s=step * SAMPLE_PERIOD_S,
                coefficient=coefficient_for(kept),
            )
        )
    return messages


def coefficient_for(values: npt.NDArray[np.float64]) -> float:
    """The smallest of 1, 2, 5 x 10^k (from 0.001) whose 16-bit samples hold ``values``."""
    largest = float(np.max(np.abs(values))) if len(values) else 0.0
    exponent = -3
    while True:
        for mantissa in (1, 2, 5):
            coefficient = mantissa * 10.0**exponent
            if largest / coefficient <= RAW_MAX:
                return round(coefficient, 6)
        exponent += 1
