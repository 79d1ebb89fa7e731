"""Tightening result messages: subscribe, push, acknowledge, and the old-result upload.

=====  ======================  ==============================================
MID    class                   data
=====  ======================  ==============================================
0060   ResultSubscribe         none; its header revision is the 0061 revision
                               asked (the no-ack flag asks no 0062)
0061   LastTighteningResult    rev 1 (23 fields) and rev 2 (46 fields), see
                               :mod:`.result_layouts`
0062   ResultAcknowledge       none
0063   ResultUnsubscribe       none
0064   OldResultRequest        tightening id (10 digits, no parameter id);
                               0 = the last result; header revision = the
                               0065 revision asked
0065   OldTighteningResult     rev 1 (11 fields) and rev 2 (28 fields)
=====  ======================  ==============================================

Fields a revision lacks are None in a message decoded at that revision;
encoding at a revision that needs them refuses None (naming the field).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from shared.openprotocol.fields import Layout, LayoutMessage, Spec
from shared.openprotocol.result_layouts import (
    LAST_RESULT_1,
    LAST_RESULT_2,
    OLD_RESULT_1,
    OLD_RESULT_2,
    BatchStatus,
    ValueStatus,
)

__all__ = [
    "BatchStatus",
    "LastTighteningResult",
    "OldResultRequest",
    "OldTighteningResult",
    "ResultAcknowledge",
    "ResultSubscribe",
    "ResultUnsubscribe",
    "ValueStatus",
]

_NO_DATA: Layout = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class ResultSubscribe(LayoutMessage):
    """0060: subscribe to 0061 at ``revision``."""

    MID: ClassVar[int] = 60
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: _NO_DATA, 2: _NO_DATA}
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class LastTighteningResult(LayoutMessage):
    """0061: the result of the tightening that just ended (torques in Nm, angles in degrees)."""

    MID: ClassVar[int] = 61
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: LAST_RESULT_1, 2: LAST_RESULT_2}
    cell_id: int
    channel_id: int
    controller_name: str
    vin: str
    job_id: int
    pset_id: int
    batch_size: int
    batch_counter: int
    tightening_ok: bool
    batch_status: BatchStatus
    torque_status: ValueStatus
    angle_status: ValueStatus
    torque_min_nm: float
    torque_max_nm: float
    torque_final_target_nm: float
    torque_nm: float
    angle_min_deg: int
    angle_max_deg: int
    angle_final_target_deg: int
    angle_deg: int
    tightening_id: int
    timestamp: str
    pset_changed: str
    # revision 2
    strategy: int | None = None
    strategy_options: int | None = None
    rundown_angle_status: ValueStatus | None = None
    current_monitoring_status: ValueStatus | None = None
    selftap_status: ValueStatus | None = None
    prevail_torque_monitoring_status: ValueStatus | None = None
    prevail_torque_compensate_status: ValueStatus | None = None
    tightening_error_status: int | None = None
    rundown_angle_min_deg: int | None = None
    rundown_angle_max_deg: int | None = None
    rundown_angle_deg: int | None = None
    current_monitoring_min_pct: int | None = None
    current_monitoring_max_pct: int | None = None
    current_monitoring_pct: int | None = None
    selftap_min_nm: float | None = None
    selftap_max_nm: float | None = None
    selftap_torque_nm: float | None = None
    prevail_torque_min_nm: float | None = None
    prevail_torque_max_nm: float | None = None
    prevail_torque_nm: float | None = None
    job_sequence_number: int | None = None
    sync_tightening_id: int | None = None
    tool_serial: str | None = None
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class ResultAcknowledge(LayoutMessage):
    """0062: the integrator received a 0061."""

    MID: ClassVar[int] = 62
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: _NO_DATA}
    ANY_REVISION: ClassVar[bool] = True
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class ResultUnsubscribe(LayoutMessage):
    """0063: no more 0061."""

    MID: ClassVar[int] = 63
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: _NO_DATA}
    ANY_REVISION: ClassVar[bool] = True
    revision: int = 1


_TIGHTENING_ID = Spec("tightening_id", "tightening id", 10)


@dataclass(frozen=True, slots=True, kw_only=True)
class OldResultRequest(LayoutMessage):
    """0064: send the result of ``tightening_id`` (0: the last one) as 0065 at ``revision``."""

    MID: ClassVar[int] = 64
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: (_TIGHTENING_ID,), 2: (_TIGHTENING_ID,)}
    tightening_id: int
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class OldTighteningResult(LayoutMessage):
    """0065: a stored result, by tightening id (torques in Nm, angles in degrees)."""

    MID: ClassVar[int] = 65
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: OLD_RESULT_1, 2: OLD_RESULT_2}
    tightening_id: int
    vin: str
    pset_id: int
    batch_counter: int
    tightening_ok: bool
    batch_status: BatchStatus
    torque_status: ValueStatus
    angle_status: ValueStatus
    torque_nm: float
    angle_deg: int
    timestamp: str
    # revision 2
    job_id: int | None = None
    strategy: int | None = None
    strategy_options: int | None = None
    batch_size: int | None = None
    rundown_angle_status: ValueStatus | None = None
    current_monitoring_status: ValueStatus | None = None
    selftap_status: ValueStatus | None = None
    prevail_torque_monitoring_status: ValueStatus | None = None
    prevail_torque_compensate_status: ValueStatus | None = None
    tightening_error_status: int | None = None
    rundown_angle_deg: int | None = None
    current_monitoring_pct: int | None = None
    selftap_torque_nm: float | None = None
    prevail_torque_nm: float | None = None
    job_sequence_number: int | None = None
    sync_tightening_id: int | None = None
    tool_serial: str | None = None
    revision: int = 1
