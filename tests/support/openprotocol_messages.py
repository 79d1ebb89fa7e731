"""Data fields of the test controller's session, tool and alarm messages.

Each layout is written from the text of the Open Protocol Specification R2.8.0
(Atlas Copco 9836 4415 01), checked against R2.16.0 where both have it:

- MID 0002 Communication start acknowledge: 5.2.2, Tables 11-16 (revisions 1-6).
- MID 0004 Command error: 5.2.4, Table 17 (MID 4 digits, error code 2 digits) and the error
  codes of Table 18 (`Error`).
- MID 0005 Command accepted: 5.2.5, Table 19 (the MID accepted, 4 digits).
- MID 0041 Tool data upload reply: 5.6.2, Tables 63-67 (revisions 1-5).
- MID 0071 Alarm: 5.10.2, Table 95 (revisions 0-1: error code of 4 characters) and Table 96
  (revision 2: 5 characters and a 50-character alarm text; R2.16.0 Table 134 has no text in
  revision 2, see `alarm`).
- MID 0074 Alarm acknowledged on controller: 5.10.5, Table 97 (the error code alone, 4
  characters, no parameter id).
- MID 0076 Alarm status: 5.10.7, Tables 98 and 99 (revisions 1 and 2).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

from tests.support.openprotocol_wire import digits, parameters, text, timestamp


class Error(IntEnum):
    """The MID 0004 error codes the test controller answers with (Table 18)."""

    INVALID_DATA = 1
    RESULT_SUBSCRIPTION_EXISTS = 9
    RESULT_SUBSCRIPTION_MISSING = 10
    ALARM_SUBSCRIPTION_EXISTS = 11
    ALARM_SUBSCRIPTION_MISSING = 12
    TIGHTENING_ID_NOT_FOUND = 15
    SUBSCRIPTION_EXISTS = 71
    SUBSCRIPTION_MISSING = 72
    SUBSCRIBED_MID_UNSUPPORTED = 73
    SUBSCRIBED_MID_REVISION_UNSUPPORTED = 74
    SUBSCRIPTION_DATA_UNSUPPORTED = 78
    CLIENT_ALREADY_CONNECTED = 96
    MID_REVISION_UNSUPPORTED = 97
    UNKNOWN_MID = 99


@dataclass(frozen=True)
class ControllerIdentity:
    """What a controller says of itself in MID 0002, 0041, 0061 and 0065."""

    name: str = "PF6000-EMU"
    cell_id: int = 1
    channel_id: int = 1
    supplier_code: str = "ACT"
    protocol_version: str = "2.8.0"
    software_version: str = "SPEC-EMU 1.0"
    tool_software_version: str = "TOOL 1.0"
    rbu_type: str = "NONE"
    controller_serial: str = "C000000001"
    system_type: int = 3  # 003 = Power Focus 6000 (Table 15)
    station_id: int = 1
    station_name: str = "STATION 1"
    tool_serial: str = "T0000000000001"
    tool_model: str = "ETV ST61"
    calibration_time_s: float = 1_700_000_000.0


def start_acknowledge(ident: ControllerIdentity, revision: int) -> str:
    """MID 0002 data field at `revision` (1-6)."""
    pairs = [
        (1, digits(ident.cell_id, 4)),
        (2, digits(ident.channel_id, 2)),
        (3, text(ident.name, 25)),
    ]
    if revision >= 2:
        pairs.append((4, text(ident.supplier_code, 3)))
    if revision >= 3:
        pairs += [
            (5, text(ident.protocol_version, 19)),
            (6, text(ident.software_version, 19)),
            (7, text(ident.tool_software_version, 19)),
        ]
    if revision >= 4:
        pairs += [(8, text(ident.rbu_type, 24)), (9, text(ident.controller_serial, 10))]
    if revision >= 5:
        pairs += [(10, digits(ident.system_type, 3)), (11, "001")]
    if revision >= 6:
        # No sequence numbering, no message linking: the application level acknowledging.
        pairs += [
            (12, "0"),
            (13, "0"),
            (14, digits(ident.station_id, 10)),
            (15, text(ident.station_name, 25)),
            (16, "1"),
        ]
    return parameters(pairs)


def command_error(mid: int, error: int) -> str:
    """MID 0004 data field: the MID refused and the two-digit error code."""
    return f"{digits(mid, 4)}{digits(error, 2)}"


def command_accepted(mid: int) -> str:
    """MID 0005 data field: the MID accepted."""
    return digits(mid, 4)


def tool_data(ident: ControllerIdentity, revision: int, tightenings: int) -> str:
    """MID 0041 data field at `revision` (1-5)."""
    calibrated = timestamp(ident.calibration_time_s)
    pairs = [
        (1, text(ident.tool_serial, 14)),
        (2, digits(tightenings, 10)),
        (3, calibrated),
        (4, text(ident.controller_serial, 10)),
    ]
    if revision >= 2:
        pairs += [
            (5, digits(10000, 6)),  # calibration value 100.00
            (6, calibrated),  # last service date
            (7, digits(tightenings, 10)),  # tightenings since service
            (8, "04"),  # 04 = ST-tool
            (9, "00"),
            (10, "000"),  # open end not used, CW, normal rotation
            (11, text(ident.software_version, 19)),
        ]
    if revision >= 3:
        pairs += [(12, digits(6000, 6)), (13, digits(100, 6)), (14, digits(60000, 6))]
    if revision >= 4:
        pairs.append((15, "01"))  # primary tool: cable
    if revision >= 5:
        pairs.append((16, text(ident.tool_model, 12)))
    return parameters(pairs)


@dataclass(frozen=True)
class Alarm:
    """An alarm of the controller: its code (E404), text and when it was raised."""

    code: str
    text: str
    time_s: float


def _alarm_code(code: str, revision: int) -> str:
    width = 5 if revision >= 2 else 4
    return code[:width].ljust(width)


def alarm(current: Alarm, revision: int, *, rev2_text: bool = True) -> str:
    """MID 0071 data field at `revision` (1 or 2); controller and tool are ready.

    R2.8.0 (Table 96) ends revision 2 with the alarm text (parameter 05, 50 characters,
    though its byte range 57-107 spans 51); R2.16.0 (Table 134) ends revision 2 at the time
    stamp and moves the text to revision 3: `rev2_text=False` sends that.
    """
    pairs = [
        (1, _alarm_code(current.code, revision)),
        (2, "1"),
        (3, "1"),
        (4, timestamp(current.time_s)),
    ]
    if revision >= 2 and rev2_text:
        pairs.append((5, current.text[:50].ljust(50)))
    return parameters(pairs)


def alarm_acknowledged(current: Alarm) -> str:
    """MID 0074 data field: the acknowledged alarm's code, four characters."""
    return _alarm_code(current.code, 1)


def alarm_status(current: Alarm | None, revision: int, now_s: float) -> str:
    """MID 0076 data field at `revision` (1 or 2): whether an alarm is active, and which."""
    code = current.code if current is not None else ""
    return parameters(
        [
            (1, "1" if current is not None else "0"),
            (2, _alarm_code(code, revision)),
            (3, "1"),
            (4, "1"),
            (5, timestamp(current.time_s if current is not None else now_s)),
        ]
    )
