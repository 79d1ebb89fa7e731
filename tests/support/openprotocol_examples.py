"""One example message of every MID and revision the codec implements."""

from __future__ import annotations

import dataclasses

from shared.openprotocol import (
    BatchStatus,
    ResolutionField,
    TraceCurve,
    TraceType,
    ValueStatus,
    VariableField,
    WireMessage,
    alarms,
    multi_spindle,
    results,
    session,
    subscriptions,
    tool_data,
)
from tests.support.openprotocol_golden import (
    LAST_RESULT_1,
    LAST_RESULT_2,
    OLD_RESULT_1,
    TOOL_DATA_2,
)

TIME = "2024-06-01:07:31:02"

OLD_RESULT_2 = results.OldTighteningResult(
    tightening_id=9_999_999_999, vin="", job_id=9999, pset_id=999, strategy=99,
    strategy_options=31, batch_size=9999, batch_counter=9999, tightening_ok=False,
    batch_status=BatchStatus.NOK, torque_status=ValueStatus.HIGH, angle_status=ValueStatus.OK,
    rundown_angle_status=ValueStatus.LOW, current_monitoring_status=ValueStatus.HIGH,
    selftap_status=ValueStatus.OK, prevail_torque_monitoring_status=ValueStatus.OK,
    prevail_torque_compensate_status=ValueStatus.OK, tightening_error_status=4_294_967_295,
    torque_nm=9999.99, angle_deg=99999, rundown_angle_deg=0, current_monitoring_pct=999,
    selftap_torque_nm=0.01, prevail_torque_nm=0.0, job_sequence_number=99999,
    sync_tightening_id=1, tool_serial="12345678901234", timestamp=TIME, revision=2,
)  # fmt: skip

SPINDLES = (
    multi_spindle.SpindleResult(1, 1, True, 1, 201.37, True, 47),
    multi_spindle.SpindleResult(2, 2, False, 2, 9999.99, False, 99999),
    multi_spindle.SpindleResult(20, 99, True, 0, 0.0, True, 0),
)
MULTI_SPINDLE_RESULT = multi_spindle.MultiSpindleResult(
    vin="WVWZZZ1JZXW000001", job_id=99, pset_id=999, batch_size=9999, batch_counter=0,
    batch_status=BatchStatus.NOT_USED, torque_min_nm=180.0, torque_max_nm=240.0,
    torque_final_target_nm=200.0, angle_min_deg=35, angle_max_deg=65,
    angle_final_target_deg=0, pset_changed=TIME, timestamp=TIME, sync_tightening_id=65535,
    ok=False, spindles=SPINDLES,
)  # fmt: skip

TRACE = TraceCurve(
    result_id=345,
    timestamp=TIME,
    trace_type=TraceType.TORQUE,
    unit=1,
    samples=(0.0, 0.25, -0.5, 81.9175, -81.92),
    parameter_fields=(VariableField(2214, "0.0025"),),
    resolution_fields=(ResolutionField(1, 5, "1", unit=202, data_type=1),),
    transducer_type=1,
    pid_fields=(VariableField(2, "0123", data_type=1, unit=0, step=1),),
)

EXAMPLES: list[WireMessage] = [
    session.CommunicationStart(revision=1),
    session.CommunicationStart(revision=2),
    session.CommunicationStart(revision=3),
    session.CommunicationStartAck(cell_id=1, channel_id=1, controller_name="PF6000"),
    session.CommunicationStartAck(
        cell_id=9999, channel_id=99, controller_name="x" * 25, supplier_code="ACT", revision=2
    ),
    session.CommunicationStartAck(
        cell_id=0,
        channel_id=0,
        controller_name="PF6000",
        supplier_code="ACT",
        open_protocol_version="2.8.0",
        controller_software_version="PF6000 4.2",
        tool_software_version="ST 1.0",
        revision=3,
    ),
    session.CommunicationStop(),
    session.CommandError(mid=64, error_code=15),
    session.CommandError(mid=9, error_code=999, revision=2),
    session.CommandAccepted(mid=900),
    session.KeepAlive(),
    subscriptions.DataSubscribe(
        mid=900, wanted_revision=1, extra_data=subscriptions.trace_extra_data([1, 2])
    ),
    subscriptions.DataUnsubscribe(mid=900, extra_data=""),
    *(tool_data.ToolDataRequest(revision=revision) for revision in range(1, 6)),
    tool_data.ToolData(
        tool_serial="B0412345", tightenings=0, last_calibration=TIME, controller_serial=""
    ),
    TOOL_DATA_2,
    dataclasses.replace(
        TOOL_DATA_2, max_torque_nm=60.0, gear_ratio=1.25, full_speed_rpm=1200.0, revision=3
    ),
    dataclasses.replace(
        TOOL_DATA_2,
        max_torque_nm=60.0,
        gear_ratio=1.25,
        full_speed_rpm=1200.0,
        primary_tool=1,
        revision=4,
    ),
    dataclasses.replace(
        TOOL_DATA_2,
        max_torque_nm=0.0,
        gear_ratio=0.0,
        full_speed_rpm=9999.99,
        primary_tool=99,
        tool_model="STB34",
        revision=5,
    ),
    results.ResultSubscribe(revision=1),
    results.ResultSubscribe(revision=2),
    LAST_RESULT_1,
    LAST_RESULT_2,
    results.ResultAcknowledge(),
    results.ResultUnsubscribe(),
    results.OldResultRequest(tightening_id=0),
    results.OldResultRequest(tightening_id=345, revision=2),
    OLD_RESULT_1,
    OLD_RESULT_2,
    alarms.AlarmSubscribe(revision=1),
    alarms.AlarmSubscribe(revision=2),
    alarms.Alarm(error_code="E851", controller_ready=False, tool_ready=True, time=TIME),
    alarms.Alarm(
        error_code="E0851",
        controller_ready=True,
        tool_ready=True,
        time=TIME,
        alarm_text="Tool overheated",
        revision=2,
    ),
    alarms.AlarmAcknowledge(),
    alarms.AlarmUnsubscribe(),
    alarms.AlarmAcknowledgedOnController(error_code="E851"),
    alarms.AlarmAcknowledgedOnController(error_code="E0851", revision=2),
    alarms.AlarmAcknowledgedOnControllerAck(),
    alarms.AlarmStatus(
        alarm_active=True, error_code="E851", controller_ready=True, tool_ready=False, time=TIME
    ),
    alarms.AlarmStatus(
        alarm_active=False,
        error_code="",
        controller_ready=True,
        tool_ready=True,
        time=TIME,
        revision=2,
    ),
    alarms.AlarmStatusAck(),
    multi_spindle.MultiSpindleStatusSubscribe(),
    multi_spindle.MultiSpindleStatus(
        sync_tightening_id=0,
        time=TIME,
        ok=False,
        spindles=multi_spindle.spindle_statuses(SPINDLES),
    ),
    multi_spindle.MultiSpindleStatusAcknowledge(),
    multi_spindle.MultiSpindleStatusUnsubscribe(),
    multi_spindle.MultiSpindleResultSubscribe(),
    multi_spindle.MultiSpindleResultSubscribe(data_no_system=0, revision=2),
    *(
        multi_spindle.MultiSpindleResultSubscribe(
            data_no_system=9_999_999_999, send_only_new=True, revision=revision
        )
        for revision in (3, 4, 5)
    ),
    *(dataclasses.replace(MULTI_SPINDLE_RESULT, revision=revision) for revision in (1, 2, 3)),
    dataclasses.replace(
        MULTI_SPINDLE_RESULT,
        system_sub_type=2,
        angle_min_deg=-9999,
        spindles=(multi_spindle.SpindleResult(1, 1, True, 1, 12.5, True, -9999),),
        revision=4,
    ),
    dataclasses.replace(
        MULTI_SPINDLE_RESULT, system_sub_type=1, job_sequence_number=65535, revision=5
    ),
    multi_spindle.MultiSpindleResultAcknowledge(),
    multi_spindle.MultiSpindleResultUnsubscribe(),
    TRACE,
    dataclasses.replace(TRACE, samples=(), pid_fields=(), parameter_fields=()),
]
