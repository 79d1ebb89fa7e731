"""Golden Open Protocol messages, written by hand from the public layouts, with their bytes."""

from __future__ import annotations

from shared.openprotocol import (
    BatchStatus,
    LastTighteningResult,
    OldTighteningResult,
    ToolData,
    ValueStatus,
)

NAME = "Airbag1".ljust(25)


VIN = "KPOL3456JKLO897".ljust(25)


LAST_RESULT_1 = LastTighteningResult(
    cell_id=1, channel_id=1, controller_name="Airbag1", vin="KPOL3456JKLO897", job_id=0,
    pset_id=4, batch_size=0, batch_counter=0, tightening_ok=False,
    batch_status=BatchStatus.OK, torque_status=ValueStatus.OK, angle_status=ValueStatus.OK,
    torque_min_nm=1.2, torque_max_nm=18.0, torque_final_target_nm=15.0, torque_nm=14.8,
    angle_min_deg=0, angle_max_deg=360, angle_final_target_deg=90, angle_deg=89,
    tightening_id=345, timestamp="2001-06-02:09:54:09", pset_changed="2001-05-29:12:34:33",
)  # fmt: skip


LAST_RESULT_1_WIRE = (
    b"02310061001         "
    b"010001" b"0201" b"03" + NAME.encode() + b"04" + VIN.encode() + b"0500" b"06004"
    b"070000" b"080000" b"090" b"101" b"111" b"12000120" b"13001800" b"14001500" b"15001480"
    b"1600000" b"1700360" b"1800090" b"1900089" b"202001-06-02:09:54:09"
    b"212001-05-29:12:34:33" b"221" b"230000000345\x00"
)  # fmt: skip


LAST_RESULT_2 = LastTighteningResult(
    cell_id=1, channel_id=1, controller_name="Airbag1", vin="KPOL3456JKLO897", job_id=1,
    pset_id=4, strategy=1, strategy_options=0, batch_size=10, batch_counter=3,
    tightening_ok=True, batch_status=BatchStatus.RUNNING, torque_status=ValueStatus.OK,
    angle_status=ValueStatus.HIGH, rundown_angle_status=ValueStatus.OK,
    current_monitoring_status=ValueStatus.OK, selftap_status=ValueStatus.OK,
    prevail_torque_monitoring_status=ValueStatus.OK,
    prevail_torque_compensate_status=ValueStatus.OK, tightening_error_status=0,
    torque_min_nm=1.2, torque_max_nm=18.0, torque_final_target_nm=15.0, torque_nm=14.8,
    angle_min_deg=0, angle_max_deg=360, angle_final_target_deg=90, angle_deg=361,
    rundown_angle_min_deg=30, rundown_angle_max_deg=120, rundown_angle_deg=100,
    current_monitoring_min_pct=10, current_monitoring_max_pct=99, current_monitoring_pct=50,
    selftap_min_nm=0.5, selftap_max_nm=2.0, selftap_torque_nm=1.0,
    prevail_torque_min_nm=0.0, prevail_torque_max_nm=3.0, prevail_torque_nm=1.5,
    tightening_id=345, job_sequence_number=7, sync_tightening_id=0, tool_serial="B0412345",
    timestamp="2001-06-02:09:54:09", pset_changed="2001-05-29:12:34:33", revision=2,
)  # fmt: skip


LAST_RESULT_2_WIRE = (
    b"03850061002         "
    b"010001" b"0201" b"03" + NAME.encode() + b"04" + VIN.encode() + b"050001" b"06004"
    b"0701" b"0800000" b"090010" b"100003" b"111" b"123" b"131" b"142" b"151" b"161" b"171"
    b"181" b"191" b"200000000000" b"21000120" b"22001800" b"23001500" b"24001480" b"2500000"
    b"2600360" b"2700090" b"2800361" b"2900030" b"3000120" b"3100100" b"32010" b"33099"
    b"34050" b"35000050" b"36000200" b"37000100" b"38000000" b"39000300" b"40000150"
    b"410000000345" b"4200007" b"4300000" b"44B0412345      " b"452001-06-02:09:54:09"
    b"462001-05-29:12:34:33\x00"
)  # fmt: skip


OLD_RESULT_1 = OldTighteningResult(
    tightening_id=345, vin="KPOL3456JKLO897", pset_id=4, batch_counter=2, tightening_ok=True,
    torque_status=ValueStatus.OK, angle_status=ValueStatus.LOW, torque_nm=14.8, angle_deg=9,
    timestamp="2001-06-02:09:54:09", batch_status=BatchStatus.NOT_USED,
)  # fmt: skip


OLD_RESULT_1_WIRE = (
    b"01180065001         "
    b"010000000345" b"02" + VIN.encode() + b"03004" b"040002" b"051" b"061" b"070"
    b"08001480" b"0900009" b"102001-06-02:09:54:09" b"112\x00"
)  # fmt: skip


TOOL_DATA_2 = ToolData(
    tool_serial="B0412345", tightenings=12345, last_calibration="2024-03-01:08:00:00",
    controller_serial="C123456789", calibration_value_nm=50.25,
    last_service="2024-06-01:07:30:00", tightenings_since_service=678, tool_type=1,
    motor_size=3, open_end_data="000", controller_software_version="PF6000 4.2", revision=2,
)  # fmt: skip


TOOL_DATA_2_WIRE = (
    b"01560041002         "
    b"01B0412345      " b"020000012345" b"032024-03-01:08:00:00" b"04C123456789"
    b"05005025" b"062024-06-01:07:30:00" b"070000000678" b"0801" b"0903" b"10000"
    b"11PF6000 4.2         \x00"
)  # fmt: skip


# Written by hand from the layout: tightening 345, torque in Nm, coefficient
# 0.01 (PID 02214), 1 ms between samples (unit 202), three samples 100, -50, 1234.
ASCII_PART = (
    b"0000000345" b"2024-06-01:07:31:02" b"000" b"02" b"01" b"001"
    b"001" b"02214" b"004" b"03" b"000" b"0000" b"0.01"
    b"001" b"00001" b"00003" b"001" b"01" b"202" b"1"
    b"00003"
)  # fmt: skip


BIG = b"\x00\x64\xff\xce\x04\xd2"


LITTLE = b"\x64\x00\xce\xff\xd2\x04"


# the specification (2.2.4): the length counts the ASCII part's NUL and the samples, and "no
# NUL character is sent after the binary data"
TRACE_WIRE = b"01170900001         " + ASCII_PART + b"\x00" + BIG
