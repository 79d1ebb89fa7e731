"""Generic data subscription (0008/0009) and the extra data that asks for 0900 traces.

0008 application data message subscription / 0009 unsubscribe, revision 1,
no parameter ids::

    subscription MID (4) | wanted revision of that MID (3) | extra data length (2) | extra data

The 0008 header revision is 0008's own; the revision of the data MID asked is
the second field. The controller answers 0005 (command accepted, data
"0008") or 0004; reading also takes data that stops after the wanted
revision as no extra data, and writing always gives the length ("00"). The
integrator acknowledges each pushed 0900 with 0005 whose data is "0900"
(:class:`~.session.CommandAccepted` with ``mid=900``); a subscription with the
header no-ack flag asks for none.

**0900 extra data** (:func:`trace_extra_data`, :func:`trace_types_of`), the
specification's Table 158 (Open Protocol 2.8.0, 5.27.1.1)::

    send alternative (1: 0 new data only, 1 from an index, 2 from a time stamp,
    3 between two indexes, 4 between two Unix times)
    | alternatives 0-2: time stamp (19) | index (10)
    | alternatives 3-4: first (10) | last (10)
    | number of trace types (2) | trace type (3) per type: 001 angle, 002 torque...

Fields not used are read as zeros or spaces, bytes after the trace types are
ignored; written: zeros, e.g. 30 zeros + "03001002003" for angle, torque and
current. The sources each reading follows: ``docs/explanation/openprotocol-bridge.md``,
"Reading what the sources disagree on".
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import ClassVar, Self

from shared.openprotocol.dialect import DEFAULT_DIALECT, Dialect
from shared.openprotocol.errors import OpenProtocolError
from shared.openprotocol.fields import Spec, decode_fields, encode_fields

_NO_LENGTH = 7  # subscription MID and wanted revision only
_HEAD = (
    Spec("mid", "subscription mid", 4, low=1),
    Spec("wanted_revision", "wanted revision", 3, low=1),
    Spec("extra_length", "extra data length", 2),
)


@dataclass(frozen=True, slots=True, kw_only=True)
class DataSubscribe:
    """0008: subscribe to the data messages of MID ``mid`` at ``wanted_revision``."""

    MID: ClassVar[int] = 8
    mid: int
    wanted_revision: int = 1
    extra_data: str = ""
    revision: int = 1

    @classmethod
    def revisions(cls) -> tuple[int, ...]:
        return (1,)

    @classmethod
    def from_data(cls, data: bytes, revision: int, dialect: Dialect = DEFAULT_DIALECT) -> Self:
        if len(data) == _NO_LENGTH:
            data += b"00"  # node-open-protocol's "0900001": no extra data length, no extra data
        values = decode_fields(data, _HEAD, cls.MID, revision)
        extra_length = values.pop("extra_length")
        assert isinstance(extra_length, int)
        extra = data[9 : 9 + extra_length]
        if len(extra) < extra_length:
            why = f"{len(extra)} bytes where the extra data length says {extra_length}"
            raise OpenProtocolError(cls.MID, "extra data", why, revision=revision)
        mid, wanted = values["mid"], values["wanted_revision"]
        assert isinstance(mid, int) and isinstance(wanted, int)
        return cls(
            mid=mid, wanted_revision=wanted, extra_data=extra.decode("latin-1"), revision=revision
        )

    def to_data(self, revision: int, dialect: Dialect = DEFAULT_DIALECT) -> bytes:
        values = {
            "mid": self.mid,
            "wanted_revision": self.wanted_revision,
            "extra_length": len(self.extra_data),
        }
        head = encode_fields(values, _HEAD, self.MID, revision)
        try:
            return head + self.extra_data.encode("latin-1")
        except UnicodeEncodeError:
            why = f"'{self.extra_data}' is not latin-1"
            raise OpenProtocolError(self.MID, "extra data", why, revision=revision) from None


@dataclass(frozen=True, slots=True, kw_only=True)
class DataUnsubscribe(DataSubscribe):
    """0009: end the subscription to MID ``mid`` (same fields as 0008)."""

    MID: ClassVar[int] = 9


_SEND_NEW, _SEND_FROM_INDEX = 0, 1
_TYPES_AT = {0: 30, 1: 30, 2: 30, 3: 21, 4: 21}  # where the number of trace types starts


def trace_extra_data(trace_types: Sequence[int], *, from_result_id: int = 0) -> str:
    """The 0008 extra data asking 0900 curves of ``trace_types`` (1 angle, 2 torque, ...).

    ``from_result_id`` 0: new results only (send alternative 0); else the
    stored results from that index on (send alternative 1).
    """
    if not 0 <= from_result_id < 10**10:
        raise OpenProtocolError(8, "extra data", f"result id {from_result_id} is not 10 digits")
    if not 1 <= len(trace_types) <= 99 or not all(0 < t < 1000 for t in trace_types):
        why = f"trace types {list(trace_types)} are not 1 to 99 numbers of 1..999"
        raise OpenProtocolError(8, "extra data", why)
    send = _SEND_FROM_INDEX if from_result_id else _SEND_NEW
    kinds = "".join(f"{t:03d}" for t in trace_types)
    return f"{send}{'0' * 19}{from_result_id:010d}{len(trace_types):02d}{kinds}"


def trace_types_of(extra_data: str) -> tuple[int, ...]:
    """The trace types a 0900 subscription's extra data asks (see :func:`trace_extra_data`)."""
    send = extra_data[:1]
    if not send.isdigit() or int(send) not in _TYPES_AT:
        raise OpenProtocolError(8, "extra data", f"'{send}' is not a send alternative (0..4)")
    at = _TYPES_AT[int(send)]
    count_text = extra_data[at : at + 2]
    if len(count_text) != 2 or not count_text.isdigit():
        raise OpenProtocolError(8, "extra data", f"'{count_text}' is not a number of trace types")
    count = int(count_text)
    kinds = extra_data[at + 2 : at + 2 + 3 * count]
    if len(kinds) != 3 * count or not kinds.isdigit():
        raise OpenProtocolError(8, "extra data", f"'{kinds}' is not {count} trace types")
    return tuple(int(kinds[i : i + 3]) for i in range(0, len(kinds), 3))
