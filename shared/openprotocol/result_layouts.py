"""Field layouts of 0061 (last tightening result) and 0065 (old tightening result).

Every field is "parameter id (2 digits) + value"; widths from the Open
Protocol specification as OpenProtocolInterpreter (``Tightening/Mid0061.cs``,
``Mid0065.cs``, absolute offsets) and the Rust ``open-protocol`` crate
(``messages/tightening_result.rs``, parameter numbers) both give them; they
agree on every field of revisions 1 and 2. Torques are hundredths of the
controller's torque unit (Nm unless configured otherwise: 0061 rev 3 says
which), angles whole degrees, current monitoring whole percent.

Lengths (header included, NUL excluded): 0061 rev 1: 231, rev 2: 385;
0065 rev 1: 118, rev 2: 226.
"""

from __future__ import annotations

import enum

from shared.openprotocol.fields import Layout, Spec, numbered


class ValueStatus(enum.IntEnum):
    """A measured value against its window (0061/0065 torque, angle, ... status)."""

    LOW = 0
    OK = 1
    HIGH = 2


class BatchStatus(enum.IntEnum):
    NOK = 0
    OK = 1
    NOT_USED = 2
    RUNNING = 3  # rev 2


def _status(attr: str, label: str) -> Spec:
    return Spec(attr, label, 1, "enum", enum=ValueStatus)


_SPECS: dict[str, Spec] = {
    spec.attr: spec
    for spec in (
        Spec("cell_id", "cell id", 4),
        Spec("channel_id", "channel id", 2),
        Spec("controller_name", "torque controller name", 25, "text"),
        Spec("vin", "vin number", 25, "text"),
        Spec("job_id", "job id", 4),  # 2 digits at 0061 rev 1, see below
        Spec("pset_id", "parameter set id", 3),
        Spec("strategy", "strategy", 2),
        Spec("strategy_options", "strategy options", 5),
        Spec("batch_size", "batch size", 4),
        Spec("batch_counter", "batch counter", 4),
        Spec("tightening_ok", "tightening status", 1, "flag"),
        Spec("batch_status", "batch status", 1, "enum", enum=BatchStatus),
        _status("torque_status", "torque status"),
        _status("angle_status", "angle status"),
        _status("rundown_angle_status", "rundown angle status"),
        _status("current_monitoring_status", "current monitoring status"),
        _status("selftap_status", "selftap status"),
        _status("prevail_torque_monitoring_status", "prevail torque monitoring status"),
        _status("prevail_torque_compensate_status", "prevail torque compensate status"),
        Spec("tightening_error_status", "tightening error status", 10),
        Spec("torque_min_nm", "torque min limit", 6, "centi"),
        Spec("torque_max_nm", "torque max limit", 6, "centi"),
        Spec("torque_final_target_nm", "torque final target", 6, "centi"),
        Spec("torque_nm", "torque final", 6, "centi"),
        Spec("angle_min_deg", "angle min", 5),
        Spec("angle_max_deg", "angle max", 5),
        Spec("angle_final_target_deg", "final angle target", 5),
        Spec("angle_deg", "angle final", 5),
        Spec("rundown_angle_min_deg", "rundown angle min", 5),
        Spec("rundown_angle_max_deg", "rundown angle max", 5),
        Spec("rundown_angle_deg", "rundown angle", 5),
        Spec("current_monitoring_min_pct", "current monitoring min", 3),
        Spec("current_monitoring_max_pct", "current monitoring max", 3),
        Spec("current_monitoring_pct", "current monitoring value", 3),
        Spec("selftap_min_nm", "selftap min", 6, "centi"),
        Spec("selftap_max_nm", "selftap max", 6, "centi"),
        Spec("selftap_torque_nm", "selftap torque", 6, "centi"),
        Spec("prevail_torque_min_nm", "prevail torque monitoring min", 6, "centi"),
        Spec("prevail_torque_max_nm", "prevail torque monitoring max", 6, "centi"),
        Spec("prevail_torque_nm", "prevail torque", 6, "centi"),
        Spec("tightening_id", "tightening id", 10),
        Spec("job_sequence_number", "job sequence number", 5),
        Spec("sync_tightening_id", "sync tightening id", 5),
        Spec("tool_serial", "tool serial number", 14, "text"),
        Spec("timestamp", "timestamp", 19, "timestamp"),
        Spec("pset_changed", "date/time of last change in parameter set settings", 19, "timestamp"),
    )
}
_JOB_ID_2 = Spec("job_id", "job id", 2)


def _layout(*attrs: str) -> Layout:
    return numbered(*(_JOB_ID_2 if attr == "job_id_2" else _SPECS[attr] for attr in attrs))


_LIMITS = (
    "torque_min_nm", "torque_max_nm", "torque_final_target_nm", "torque_nm",
    "angle_min_deg", "angle_max_deg", "angle_final_target_deg", "angle_deg",
)  # fmt: skip
_REV2_STATUSES = (
    "rundown_angle_status", "current_monitoring_status", "selftap_status",
    "prevail_torque_monitoring_status", "prevail_torque_compensate_status",
    "tightening_error_status",
)  # fmt: skip

LAST_RESULT_1 = _layout(
    "cell_id", "channel_id", "controller_name", "vin", "job_id_2", "pset_id", "batch_size",
    "batch_counter", "tightening_ok", "torque_status", "angle_status", *_LIMITS, "timestamp",
    "pset_changed", "batch_status", "tightening_id",
)  # fmt: skip
LAST_RESULT_2 = _layout(
    "cell_id", "channel_id", "controller_name", "vin", "job_id", "pset_id", "strategy",
    "strategy_options", "batch_size", "batch_counter", "tightening_ok", "batch_status",
    "torque_status", "angle_status", *_REV2_STATUSES, *_LIMITS,
    "rundown_angle_min_deg", "rundown_angle_max_deg", "rundown_angle_deg",
    "current_monitoring_min_pct", "current_monitoring_max_pct", "current_monitoring_pct",
    "selftap_min_nm", "selftap_max_nm", "selftap_torque_nm",
    "prevail_torque_min_nm", "prevail_torque_max_nm", "prevail_torque_nm",
    "tightening_id", "job_sequence_number", "sync_tightening_id", "tool_serial", "timestamp",
    "pset_changed",
)  # fmt: skip
OLD_RESULT_1 = _layout(
    "tightening_id", "vin", "pset_id", "batch_counter", "tightening_ok", "torque_status",
    "angle_status", "torque_nm", "angle_deg", "timestamp", "batch_status",
)  # fmt: skip
OLD_RESULT_2 = _layout(
    "tightening_id", "vin", "job_id", "pset_id", "strategy", "strategy_options", "batch_size",
    "batch_counter", "tightening_ok", "batch_status", "torque_status", "angle_status",
    *_REV2_STATUSES, "torque_nm", "angle_deg", "rundown_angle_deg", "current_monitoring_pct",
    "selftap_torque_nm", "prevail_torque_nm", "job_sequence_number", "sync_tightening_id",
    "tool_serial", "timestamp",
)  # fmt: skip
