"""A multi-spindle system's synchronised cycle in the words of Open Protocol: 0091, 0101. Pure.

The simulated controller as a multi-spindle system (``[station] spindles``
above 1) tightens a part's bolts in one cycle, a spindle each; after the
cycle it says the cycle's common status (0091) and result (0101, revision 1
to 5: revision 4 adds the system sub type, 001 a tightening system, revision
5 the job sequence number, 0 unused) to whoever subscribed. Each spindle is
its channel (01..N) and its number in the sync list; the sync tightening id
counts the cycles (1 to 65535, then 1 again). The common status is OK only
when every spindle's tightening is; a spindle's torque status is its 0061's,
its angle status OK when its angle is within its window. The cycle's figures
(VIN, parameter set, batch, limits, targets, time) are its first spindle's.
"""

from __future__ import annotations

from collections.abc import Sequence

from services.rig.openprotocol.result_messages import ControllerIdentity
from services.rig.openprotocol.tightening import Tightening
from shared.openprotocol import (
    BatchStatus,
    MultiSpindleResult,
    MultiSpindleStatus,
    SpindleResult,
)
from shared.openprotocol.multi_spindle import spindle_statuses

#: 0101's torque status of each figure status
_TORQUE_STATUS = {"low": 0, "ok": 1, "high": 2}
_BATCH_STATUS = {"nok": BatchStatus.NOK, "ok": BatchStatus.OK, "not_used": BatchStatus.NOT_USED}
#: the system sub type a tightening system says (0101 revision 4 on)
TIGHTENING_SYSTEM = 1


def spindle_results(cycle: Sequence[Tightening]) -> tuple[SpindleResult, ...]:
    return tuple(
        SpindleResult(
            spindle=t.channel_id,
            channel_id=t.channel_id,
            ok=t.ok,
            torque_status=_TORQUE_STATUS[t.torque_status],
            torque_nm=t.final_torque_nm,
            angle_ok=t.angle_status == "ok",
            angle_deg=round(t.final_angle_deg),
        )
        for t in cycle
    )


def cycle_result(
    cycle: Sequence[Tightening], revision: int, identity: ControllerIdentity
) -> MultiSpindleResult:
    """The 0101 of the cycle of ``cycle`` (every spindle's tightening) at ``revision``."""
    first = cycle[0]
    ended_ns = max(t.ended_ns for t in cycle)
    return MultiSpindleResult(
        vin=first.vin,
        job_id=0,
        pset_id=first.program_id,
        batch_size=first.batch_size,
        batch_counter=first.batch_counter,
        batch_status=_BATCH_STATUS[first.batch_status],
        torque_min_nm=first.torque_min_nm,
        torque_max_nm=first.torque_max_nm,
        torque_final_target_nm=first.torque_target_nm,
        angle_min_deg=round(first.angle_min_deg),
        angle_max_deg=round(first.angle_max_deg),
        angle_final_target_deg=round(first.angle_target_deg),
        pset_changed=identity.timestamp(first.ended_ns),
        timestamp=identity.timestamp(ended_ns),
        sync_tightening_id=first.sync_tightening_id,
        ok=all(t.ok for t in cycle),
        spindles=spindle_results(cycle),
        system_sub_type=TIGHTENING_SYSTEM if revision >= 4 else None,
        job_sequence_number=0 if revision >= 5 else None,
        revision=revision,
    )


def cycle_status(cycle: Sequence[Tightening], identity: ControllerIdentity) -> MultiSpindleStatus:
    """The 0091 of the cycle of ``cycle``."""
    return MultiSpindleStatus(
        sync_tightening_id=cycle[0].sync_tightening_id,
        time=identity.timestamp(max(t.ended_ns for t in cycle)),
        ok=all(t.ok for t in cycle),
        spindles=spindle_statuses(spindle_results(cycle)),
    )
