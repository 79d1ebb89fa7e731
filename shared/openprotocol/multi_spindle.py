"""Multi-spindle status and result messages: 0090-0093 and 0100-0103.

A multi-spindle system (a Power Focus sync master, a PowerMACS station)
tightens several bolts in one synchronised cycle and says of each cycle its
common status and each spindle's (0091), or its common result with each
spindle's torque and angle (0101). Open Protocol Specification R2.8.0,
5.12 (Tables 102-107):

=====  =============================  =============================================
MID    class                          data (parameter ids 01.. unless said)
=====  =============================  =============================================
0090   MultiSpindleStatusSubscribe    none
0091   MultiSpindleStatus             spindles (2), sync tightening id (5), time
                                      (19), sync overall status (1), spindle
                                      status (5 × spindles: number 2, channel 2,
                                      status 1)
0092   MultiSpindleStatusAcknowledge  none
0093   MultiSpindleStatusUnsubscribe  none
0100   MultiSpindleResultSubscribe    rev 1: none; rev 2: data no. system (10
                                      digits, no id); rev 3-5: + send only new
                                      data (1); its header revision is the 0101
                                      revision asked
0101   MultiSpindleResult             rev 1-3: spindles (2), VIN (25), job (2),
                                      parameter set (3), batch size (4) and
                                      counter (4), batch status (1), torque min,
                                      max, final target (6 each, hundredths of
                                      Nm), angle min, max, final target (5 each,
                                      degrees), time of the last parameter set
                                      change (19), time (19), sync tightening id
                                      (5), sync overall status (1), spindle
                                      results (18 × spindles, below); rev 4: +
                                      system sub type (3); rev 5: + job sequence
                                      number (5)
0102   MultiSpindleResultAcknowledge  none
0103   MultiSpindleResultUnsubscribe  none
=====  =============================  =============================================

A spindle's result in 0101 (18 bytes): spindle number (2, its place in the
sync list), channel id (2), its overall status (1, 0 NOK 1 OK), torque status
(1: 0 low, 1 OK, 2 high; a revision 4 press: 0 NOK, 1 OK), torque (6,
hundredths), angle status (1, 0 NOK 1 OK), angle (5, degrees). Revision 4
and 5 carry a press's force and stroke in the same places; a stroke may be
negative ("-9999", hundredths of mm), so those angle fields read a sign.

Sources: the specification's text (its 0091 example is one of
``tests/data/openprotocol/examples``) and OpenProtocolInterpreter's
``MultiSpindle/TestMid0090.cs`` .. ``TestMid0103.cs``, whose messages decode
and encode here byte for byte; the Rust ``open-protocol`` crate's
``multi_spindle_*.rs`` (a "spindles running" field, the fields in another order)
is not followed. An acknowledge and an unsubscribe are read and written at
any revision (they carry nothing), as 0062 and 0063 are.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import ClassVar, Self

from shared.openprotocol.dialect import DEFAULT_DIALECT, Dialect
from shared.openprotocol.errors import OpenProtocolError
from shared.openprotocol.fields import (
    Layout,
    LayoutMessage,
    Spec,
    decode_fields,
    encode_fields,
    layout_width,
)
from shared.openprotocol.result_layouts import BatchStatus

__all__ = [
    "MultiSpindleResult",
    "MultiSpindleResultAcknowledge",
    "MultiSpindleResultSubscribe",
    "MultiSpindleResultUnsubscribe",
    "MultiSpindleStatus",
    "MultiSpindleStatusAcknowledge",
    "MultiSpindleStatusSubscribe",
    "MultiSpindleStatusUnsubscribe",
    "SpindleResult",
    "SpindleStatus",
]

#: the most spindles a multiple holds (two digits)
MAX_SPINDLES = 99


@dataclass(frozen=True, slots=True)
class SpindleStatus:
    """One spindle of a 0091: its number in the sync list, its channel, OK or not."""

    spindle: int
    channel_id: int
    ok: bool


@dataclass(frozen=True, slots=True)
class SpindleResult:
    """One spindle of a 0101: its status, final torque (Nm; a press's force, kN) and angle
    (degrees; a press's stroke, hundredths of mm)."""

    spindle: int
    channel_id: int
    ok: bool
    torque_status: int  # 0 low, 1 OK, 2 high (revision 4 on: 0 NOK, 1 OK)
    torque_nm: float
    angle_ok: bool
    angle_deg: int


def _with_ids(*specs: Spec, first: int = 1) -> Layout:
    return tuple(
        Spec(s.attr, s.label, s.width, s.kind, first + i, s.low, s.high, s.enum)
        for i, s in enumerate(specs)
    )


_SPINDLES = Spec("spindles", "number of spindles", 2, low=1, high=MAX_SPINDLES)
_SYNC_ID = Spec("sync_tightening_id", "sync tightening id", 5, high=65535)
_OVERALL = Spec("ok", "sync overall status", 1, "flag")

_STATUS_HEAD = _with_ids(_SPINDLES, _SYNC_ID, Spec("time", "time", 19, "timestamp"), _OVERALL)
_STATUS_ENTRY = (
    Spec("spindle", "spindle number", 2, low=1, high=MAX_SPINDLES),
    Spec("channel_id", "channel id", 2),
    Spec("ok", "spindle status", 1, "flag"),
)


def _result_head(revision: int) -> Layout:
    stroke_low = -9999 if revision >= 4 else 0  # a press's stroke, revision 4 on
    return _with_ids(
        _SPINDLES,
        Spec("vin", "vin number", 25, "text"),
        Spec("job_id", "job id", 2),
        Spec("pset_id", "parameter set id", 3),
        Spec("batch_size", "batch size", 4),
        Spec("batch_counter", "batch counter", 4),
        Spec("batch_status", "batch status", 1, "enum", enum=BatchStatus),
        Spec("torque_min_nm", "torque min limit", 6, "centi"),
        Spec("torque_max_nm", "torque max limit", 6, "centi"),
        Spec("torque_final_target_nm", "torque final target", 6, "centi"),
        Spec("angle_min_deg", "angle min", 5, low=stroke_low),
        Spec("angle_max_deg", "angle max", 5, low=stroke_low),
        Spec("angle_final_target_deg", "final angle target", 5, low=stroke_low),
        Spec("pset_changed", "date/time of last change in parameter set settings", 19, "timestamp"),
        Spec("timestamp", "time stamp", 19, "timestamp"),
        _SYNC_ID,
        _OVERALL,
    )


def _result_entry(revision: int) -> Layout:
    return (
        Spec("spindle", "spindle number", 2, low=1, high=MAX_SPINDLES),
        Spec("channel_id", "channel id", 2),
        Spec("ok", "spindle overall status", 1, "flag"),
        Spec("torque_status", "spindle torque status", 1, high=2),
        Spec("torque_nm", "spindle torque", 6, "centi"),
        Spec("angle_ok", "spindle angle status", 1, "flag"),
        Spec("angle_deg", "spindle angle", 5, low=-9999 if revision >= 4 else 0),
    )


_RESULT_TAIL: dict[int, Layout] = {
    1: (),
    2: (),
    3: (),
    4: _with_ids(Spec("system_sub_type", "system sub type", 3), first=19),
    5: _with_ids(
        Spec("system_sub_type", "system sub type", 3),
        Spec("job_sequence_number", "job sequence number", 5, high=65535),
        first=19,
    ),
}


def _entries(
    data: bytes, at: int, count: int, entry: Layout, mid: int, revision: int, label: str
) -> tuple[list[dict[str, object]], int]:
    """``count`` entries of ``entry`` from ``data`` at ``at``; the values and where they end."""
    width = layout_width(entry)
    values = []
    for index in range(count):
        part = data[at + index * width : at + (index + 1) * width]
        if len(part) < width:
            why = f"data ends at byte {len(data)}: {count} spindles need {count * width} bytes"
            raise OpenProtocolError(mid, label, why, revision=revision)
        values.append(decode_fields(part, entry, mid, revision))
    return values, at + count * width


def _entry_id(data: bytes, at: int, pid: int, mid: int, revision: int, label: str) -> int:
    if data[at : at + 2] != f"{pid:02d}".encode():
        found = data[at : at + 2].decode("latin-1")
        why = f"parameter id '{found}' where {pid:02d} is due"
        raise OpenProtocolError(mid, label, why, revision=revision)
    return at + 2


def _check_count(spindles: int, listed: int, mid: int, revision: int) -> None:
    if spindles != listed:
        why = f"{listed} spindles listed where the message says {spindles}"
        raise OpenProtocolError(mid, "number of spindles", why, revision=revision)


@dataclass(frozen=True, slots=True, kw_only=True)
class MultiSpindleStatusSubscribe(LayoutMessage):
    """0090: subscribe to 0091."""

    MID: ClassVar[int] = 90
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: ()}
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class MultiSpindleStatus:
    """0091: after each sync tightening, the multiple's common status and each spindle's."""

    MID: ClassVar[int] = 91
    sync_tightening_id: int
    time: str
    ok: bool
    spindles: tuple[SpindleStatus, ...] = field(default_factory=tuple)
    revision: int = 1

    @classmethod
    def revisions(cls) -> tuple[int, ...]:
        return (1,)

    @classmethod
    def from_data(cls, data: bytes, revision: int, dialect: Dialect = DEFAULT_DIALECT) -> Self:
        head = decode_fields(data, _STATUS_HEAD, cls.MID, revision)
        at = _entry_id(data, layout_width(_STATUS_HEAD), 5, cls.MID, revision, "spindle status")
        count = int(head["spindles"])  # type: ignore[call-overload]
        entries, _ = _entries(data, at, count, _STATUS_ENTRY, cls.MID, revision, "spindle status")
        return cls(
            sync_tightening_id=int(head["sync_tightening_id"]),  # type: ignore[call-overload]
            time=str(head["time"]),
            ok=bool(head["ok"]),
            spindles=tuple(SpindleStatus(**entry) for entry in entries),  # type: ignore[arg-type]
            revision=revision,
        )

    def to_data(self, revision: int, dialect: Dialect = DEFAULT_DIALECT) -> bytes:
        values = {
            "spindles": len(self.spindles),
            "sync_tightening_id": self.sync_tightening_id,
            "time": self.time,
            "ok": self.ok,
        }
        head = encode_fields(values, _STATUS_HEAD, self.MID, revision)
        entries = b"".join(
            encode_fields(
                {"spindle": s.spindle, "channel_id": s.channel_id, "ok": s.ok},
                _STATUS_ENTRY,
                self.MID,
                revision,
            )
            for s in self.spindles
        )
        return head + b"05" + entries


@dataclass(frozen=True, slots=True, kw_only=True)
class MultiSpindleStatusAcknowledge(LayoutMessage):
    """0092: the integrator received a 0091."""

    MID: ClassVar[int] = 92
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: ()}
    ANY_REVISION: ClassVar[bool] = True
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class MultiSpindleStatusUnsubscribe(LayoutMessage):
    """0093: no more 0091."""

    MID: ClassVar[int] = 93
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: ()}
    ANY_REVISION: ClassVar[bool] = True
    revision: int = 1


_DATA_NO_SYSTEM = Spec("data_no_system", "data no system", 10)
_ONLY_NEW = Spec("send_only_new", "send only new data", 1, "flag")


@dataclass(frozen=True, slots=True, kw_only=True)
class MultiSpindleResultSubscribe(LayoutMessage):
    """0100: subscribe to 0101 at ``revision``; revision 2 on rewinds to the cycle after
    ``data_no_system`` (0: the oldest kept), revision 3 on ``send_only_new`` sends none of the
    results kept before."""

    MID: ClassVar[int] = 100
    LAYOUTS: ClassVar[dict[int, Layout]] = {
        1: (),
        2: (_DATA_NO_SYSTEM,),
        3: (_DATA_NO_SYSTEM, _ONLY_NEW),
        4: (_DATA_NO_SYSTEM, _ONLY_NEW),
        5: (_DATA_NO_SYSTEM, _ONLY_NEW),
    }
    data_no_system: int | None = None
    send_only_new: bool | None = None
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class MultiSpindleResult:
    """0101: after each sync tightening, its common result and each spindle's torque and
    angle (torques in Nm, angles in degrees)."""

    MID: ClassVar[int] = 101
    vin: str
    job_id: int
    pset_id: int
    batch_size: int
    batch_counter: int
    batch_status: BatchStatus
    torque_min_nm: float
    torque_max_nm: float
    torque_final_target_nm: float
    angle_min_deg: int
    angle_max_deg: int
    angle_final_target_deg: int
    pset_changed: str
    timestamp: str
    sync_tightening_id: int
    ok: bool
    spindles: tuple[SpindleResult, ...] = field(default_factory=tuple)
    # revision 4 (001 a tightening system, 002 one of presses), revision 5
    system_sub_type: int | None = None
    job_sequence_number: int | None = None
    revision: int = 1

    @classmethod
    def revisions(cls) -> tuple[int, ...]:
        return tuple(sorted(_RESULT_TAIL))

    @classmethod
    def from_data(cls, data: bytes, revision: int, dialect: Dialect = DEFAULT_DIALECT) -> Self:
        layout = _result_head(revision)
        head = decode_fields(data, layout, cls.MID, revision)
        label = "spindle status"
        at = _entry_id(data, layout_width(layout), 18, cls.MID, revision, label)
        count = int(head.pop("spindles"))  # type: ignore[call-overload]
        entries, at = _entries(data, at, count, _result_entry(revision), cls.MID, revision, label)
        tail = decode_fields(data[at:], _RESULT_TAIL[revision], cls.MID, revision)
        spindles = tuple(SpindleResult(**entry) for entry in entries)  # type: ignore[arg-type]
        return cls(**head, **tail, spindles=spindles, revision=revision)  # type: ignore[arg-type]

    def to_data(self, revision: int, dialect: Dialect = DEFAULT_DIALECT) -> bytes:
        layout = _result_head(revision)
        values: dict[str, object] = {spec.attr: getattr(self, spec.attr, None) for spec in layout}
        values["spindles"] = len(self.spindles)
        entry = _result_entry(revision)
        entries = b"".join(
            encode_fields(
                {spec.attr: getattr(s, spec.attr) for spec in entry}, entry, self.MID, revision
            )
            for s in self.spindles
        )
        tail_layout = _RESULT_TAIL[revision]
        tail = encode_fields(
            {spec.attr: getattr(self, spec.attr) for spec in tail_layout},
            tail_layout,
            self.MID,
            revision,
        )
        return encode_fields(values, layout, self.MID, revision) + b"18" + entries + tail


@dataclass(frozen=True, slots=True, kw_only=True)
class MultiSpindleResultAcknowledge(LayoutMessage):
    """0102: the integrator received a 0101."""

    MID: ClassVar[int] = 102
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: ()}
    ANY_REVISION: ClassVar[bool] = True
    revision: int = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class MultiSpindleResultUnsubscribe(LayoutMessage):
    """0103: no more 0101."""

    MID: ClassVar[int] = 103
    LAYOUTS: ClassVar[dict[int, Layout]] = {1: ()}
    ANY_REVISION: ClassVar[bool] = True
    revision: int = 1


def spindle_statuses(spindles: Sequence[SpindleResult]) -> tuple[SpindleStatus, ...]:
    """A 0101's spindles as a 0091 says them."""
    return tuple(SpindleStatus(s.spindle, s.channel_id, s.ok) for s in spindles)
