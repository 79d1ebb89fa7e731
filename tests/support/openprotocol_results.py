"""Tightening results and their MID 0061 / MID 0065 data fields, from the specification's tables.

Source: Open Protocol Specification R2.8.0 (Atlas Copco 9836 4415 01), section 5.8:

- MID 0061 Last tightening result data: Table 76 (revision 1, parameters 01-23), Table 59
  (revision 2, parameters 01-46), Tables 77-81 (revisions 3-7 add 47-49, 50-52, 53, 54-55,
  56-57). The MID 0060 header revision chooses the revision (5.8.1).
- MID 0065 Old tightening result upload reply: Table 85 (revision 1, parameters 01-11),
  Table 86 (revision 2, 01-28), Tables 87-91 (revisions 3-7 add 29-30, 31-33, 34, 35-36,
  37-38). The MID 0064 header revision chooses it; its data is the tightening id, 10 digits,
  0 meaning the newest (5.8.5, Table 84).

Torques are hundredths of N·m in 6 digits ("multiplied by 100 and sent as an integer (2
decimals truncated)"), angles whole degrees in 5 digits, statuses 0=Low 1=OK 2=High, batch
status 0=NOK 1=OK 2=not used. Fields the test controller has nothing for are sent as
zeros (numbers, bit fields), 1 (the status of a check that passed) or spaces (text).
"""

from __future__ import annotations

from dataclasses import dataclass

from tests.support.openprotocol_messages import ControllerIdentity
from tests.support.openprotocol_wire import digits, hundredths, parameters, text, timestamp, whole

#: Highest MID 0061 and MID 0065 revision written here.
HIGHEST_RESULT_REVISION = 7


@dataclass(frozen=True)
class TighteningResult:
    """One tightening as the controller stores it."""

    tightening_id: int
    torque_nm: float
    angle_deg: float
    ok: bool
    pset: int
    vin: str
    batch_size: int
    batch_counter: int
    torque_min_nm: float
    torque_max_nm: float
    torque_target_nm: float
    angle_min_deg: float
    angle_max_deg: float
    angle_target_deg: float
    time_s: float
    pset_changed_s: float
    job_id: int = 0

    @property
    def torque_status(self) -> int:
        return _status(self.torque_nm, self.torque_min_nm, self.torque_max_nm)

    @property
    def angle_status(self) -> int:
        return _status(self.angle_deg, self.angle_min_deg, self.angle_max_deg)

    @property
    def batch_status(self) -> int:
        if self.batch_size == 0:
            return 2
        return int(self.ok and self.batch_counter >= self.batch_size)


def _status(value: float, low: float, high: float) -> int:
    return 0 if value < low else 2 if value > high else 1


def _torque(value_nm: float) -> str:
    return digits(hundredths(value_nm), 6)


def _angle(value_deg: float) -> str:
    return digits(whole(value_deg), 5)


def last_result_fields(
    result: TighteningResult, revision: int, ident: ControllerIdentity
) -> list[tuple[int, str]]:
    """MID 0061 parameters (id, value text) at `revision` (1-7)."""
    r = result
    head = [
        (1, digits(ident.cell_id, 4)),
        (2, digits(ident.channel_id, 2)),
        (3, text(ident.name, 25)),
        (4, text(r.vin, 25)),
    ]
    if revision == 1:
        return [
            *head,
            (5, digits(r.job_id, 2)),
            (6, digits(r.pset, 3)),
            (7, digits(r.batch_size, 4)),
            (8, digits(r.batch_counter, 4)),
            (9, str(int(r.ok))),
            (10, str(r.torque_status)),
            (11, str(r.angle_status)),
            (12, _torque(r.torque_min_nm)),
            (13, _torque(r.torque_max_nm)),
            (14, _torque(r.torque_target_nm)),
            (15, _torque(r.torque_nm)),
            (16, _angle(r.angle_min_deg)),
            (17, _angle(r.angle_max_deg)),
            (18, _angle(r.angle_target_deg)),
            (19, _angle(r.angle_deg)),
            (20, timestamp(r.time_s)),
            (21, timestamp(r.pset_changed_s)),
            (22, str(r.batch_status)),
            (23, digits(r.tightening_id, 10)),
        ]
    pairs = [
        *head,
        (5, digits(r.job_id, 4)),
        (6, digits(r.pset, 3)),
        (7, "02"),  # strategy: torque control / angle monitoring
        (8, "00000"),  # strategy options (bit field)
        (9, digits(r.batch_size, 4)),
        (10, digits(r.batch_counter, 4)),
        (11, str(int(r.ok))),
        (12, str(r.batch_status)),
        (13, str(r.torque_status)),
        (14, str(r.angle_status)),
        *[(pid, "1") for pid in range(15, 20)],  # rundown, current, self-tap, PVT statuses
        (20, "0" * 10),  # tightening error status (bit field)
        (21, _torque(r.torque_min_nm)),
        (22, _torque(r.torque_max_nm)),
        (23, _torque(r.torque_target_nm)),
        (24, _torque(r.torque_nm)),
        (25, _angle(r.angle_min_deg)),
        (26, _angle(r.angle_max_deg)),
        (27, _angle(r.angle_target_deg)),
        (28, _angle(r.angle_deg)),
        (29, "00000"),  # rundown angle min
        (30, "00000"),  # rundown angle max
        (31, "00000"),  # rundown angle
        (32, "000"),  # current monitoring min, max, value (%)
        (33, "000"),
        (34, "000"),
        *[(pid, "000000") for pid in range(35, 41)],  # self-tap and prevail torques
        (41, digits(r.tightening_id, 10)),
        (42, "00000"),  # job sequence number
        (43, "00000"),  # sync tightening id
        (44, text(ident.tool_serial, 14)),
        (45, timestamp(r.time_s)),
        (46, timestamp(r.pset_changed_s)),
    ]
    pairs += _later_revisions(r, revision, first_pid=47)
    if revision >= 7:
        angle = digits(whole(r.angle_deg) * 100, 7)
        pairs += [(56, angle), (57, angle)]  # compensated angle, final angle decimal
    return pairs


def _later_revisions(r: TighteningResult, revision: int, first_pid: int) -> list[tuple[int, str]]:
    """The additions of revisions 3-6, the same in MID 0061 (from 47) and MID 0065 (from 29)."""
    values: list[str] = []
    if revision >= 3:
        if first_pid == 47:  # MID 0061 revision 3 also names the Pset
            values.append(text(f"PSET {r.pset}", 25))
        values += ["1", "01"]  # torque values unit 1 = Nm; result type 01 = tightening
    if revision >= 4:
        values += [" " * 25] * 3  # identifier result parts 2-4
    if revision >= 5:
        values.append("    ")  # customer tightening error code
    if revision >= 6:
        values += ["000000", "0" * 10]  # PVT compensate value; tightening error status 2
    return list(enumerate(values, start=first_pid))


def last_result(result: TighteningResult, revision: int, ident: ControllerIdentity) -> str:
    """MID 0061 data field at `revision`."""
    return parameters(last_result_fields(result, revision, ident))


def old_result_fields(
    result: TighteningResult, revision: int, ident: ControllerIdentity
) -> list[tuple[int, str]]:
    """MID 0065 parameters (id, value text) at `revision` (1-7)."""
    r = result
    if revision == 1:
        return [
            (1, digits(r.tightening_id, 10)),
            (2, text(r.vin, 25)),
            (3, digits(r.pset, 3)),
            (4, digits(r.batch_counter, 4)),
            (5, str(int(r.ok))),
            (6, str(r.torque_status)),
            (7, str(r.angle_status)),
            (8, _torque(r.torque_nm)),
            (9, _angle(r.angle_deg)),
            (10, timestamp(r.time_s)),
            (11, str(r.batch_status)),
        ]
    pairs = [
        (1, digits(r.tightening_id, 10)),
        (2, text(r.vin, 25)),
        (3, digits(r.job_id, 4)),
        (4, digits(r.pset, 3)),
        (5, "02"),
        (6, "00000"),
        (7, digits(r.batch_size, 4)),
        (8, digits(r.batch_counter, 4)),
        (9, str(int(r.ok))),
        (10, str(r.batch_status)),
        (11, str(r.torque_status)),
        (12, str(r.angle_status)),
        *[(pid, "1") for pid in range(13, 18)],
        (18, "0" * 10),
        (19, _torque(r.torque_nm)),
        (20, _angle(r.angle_deg)),
        (21, "00000"),  # rundown angle
        (22, "000"),  # current monitoring value
        (23, "000000"),  # self-tap torque
        (24, "000000"),  # prevail torque
        (25, "00000"),
        (26, "00000"),
        (27, text(ident.tool_serial, 14)),
        (28, timestamp(r.time_s)),
    ]
    pairs += _later_revisions(r, revision, first_pid=29)
    if revision >= 7:
        pairs += [(37, digits(ident.station_id, 10)), (38, text(ident.station_name, 25))]
    return pairs


def old_result(result: TighteningResult, revision: int, ident: ControllerIdentity) -> str:
    """MID 0065 data field at `revision`."""
    return parameters(old_result_fields(result, revision, ident))
