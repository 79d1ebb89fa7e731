"""What tool controllers say, as boltwatch carries it on the line.

Re-exported by :mod:`shared.contract.messages` (``from shared.contract.messages import ToolData``
works as for every message); kept apart so each file holds one kind of
message. Same rules as every message there: frozen dataclasses, one JSON
object on the wire, every field bounded (:mod:`shared.contract.message_fields`).

- :class:`ControllerResult` (with :class:`ControllerStep`,
  :class:`ControllerFunction`): a controller's own result of one run
  (``boltwatch import``; a controller bridge the same);
- :class:`ToolData`: what a controller says of its tool (Open Protocol MID
  0041): serial, its own tightening counters, calibration and service dates;
- :class:`ControllerAlarm`: an alarm of a controller (MIDs 0071, 0074, 0076:
  raised, acknowledged on the controller, the alarm status);
- :class:`BridgeStats`: a controller bridge's counters (``boltwatch serve
  openprotocol``), once a second.

Channels: ``controller``, ``tool_data``, ``alarms``, ``openprotocol``
(:mod:`shared.contract.channels`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated, Literal

from shared.contract.message_fields import (
    WIRE_CONFIG,
    Count,
    Id,
    Int64,
    NumberRange,
    StationId,
    TextRange,
    TimeNs,
)

#: a serial, code or name as a controller gives it (Open Protocol's fields are at most
#: 40 characters; 64 leaves room for other controllers)
ControllerText = Annotated[str, TextRange(64)]
#: an Open Protocol MID revision (three ASCII digits in the message header)
Revision = Annotated[int, NumberRange(1, 999)]
#: what an alarm message says: raised (0071), acknowledged on the controller (0074), the
#: controller's alarm status (0076)
AlarmKind = Literal["raised", "acknowledged", "status"]
#: what a run did to its joint: tightened it (turning forward), or loosened it (turning back)
RunOperation = Literal["tightening", "loosening"]


@dataclass(frozen=True, slots=True)
class ControllerFunction:
    """One function of a controller step, with its nominal and actual value.

    Tightening functions (``TF ...``) end the step when reached; monitoring
    functions (``MF ...``, ``MFs ...``) are windows the step must stay in.
    Values are in the function's own unit: torque in the run's
    ``torque_unit``, angle in degrees, time in seconds.
    """

    __pydantic_config__ = WIRE_CONFIG

    name: str  # as the controller names it, e.g. "TF Torque", "MFs TorqueMax"
    nominal: float | None  # ``nom``; None when the controller gave none
    actual: float | None  # ``act``


@dataclass(frozen=True, slots=True)
class ControllerStep:
    """One step of a controller's tightening program and how it went."""

    __pydantic_config__ = WIRE_CONFIG

    name: str  # e.g. "Finding", "Thread forming", "Tightening 1.4"
    result: str  # "OK" or "NOK" as the controller wrote it ("" when it wrote none)
    quality_code: str
    samples: Count  # samples of the step's graph
    functions: list[ControllerFunction] = field(default_factory=list)


@dataclass(frozen=True, slots=True)
class ControllerResult:
    """A tool controller's own result of one run: its verdict, codes and every step's values.

    Published once per run, when it ended (imported controller runs; a
    controller bridge would publish the same). Batch counters are the
    controller's, ``-1`` where it keeps no batch, None where the file had none.
    """

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    run_id: Id
    tool_id: Id
    program_id: Id
    time_ns: TimeNs  # the run's last sample
    result: str  # "OK" or "NOK": the controller's verdict on the whole run
    quality_code: str
    part_id: str  # ``id code``: the part (work piece) the run tightened
    torque_unit: str
    # trailing samples of the last step's graph that are the tool unloading (``torsion release``)
    torsion_release_samples: Count | None
    batch_number: Int64 | None
    batch_ok: Int64 | None
    batch_nok: Int64 | None
    batch_max_ok: Int64 | None
    batch_max_nok: Int64 | None
    batch_canceled: Int64 | None
    batch_direction_ok: Int64 | None
    batch_direction_nok: Int64 | None
    steps: list[ControllerStep] = field(default_factory=list)
    # a loosening: every step that says its speed turns the tool back (a negative speed)
    operation: RunOperation = "tightening"


@dataclass(frozen=True, slots=True)
class ToolData:
    """What a controller says of its tool (Open Protocol MID 0041), when it says it.

    Kept by the wear ledger per (station, tool_id): the serial is what makes
    the station's tool id a tool of the plant. Fields the controller's
    revision of 0041 does not carry are None.
    """

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    tool_id: Id  # the station file's tool id (``station.tool_id``)
    time_ns: TimeNs  # when the bridge received it
    tool_serial: ControllerText  # as the controller gives it
    controller_serial: ControllerText | None
    tightenings: Count | None  # the tool's own counter of tightenings
    tightenings_since_service: Count | None
    last_calibration_ns: TimeNs | None
    last_service_ns: TimeNs | None  # the controller's date of the tool's last service
    calibration_value_nm: float | None
    tool_type: ControllerText | None
    tool_model: ControllerText | None
    controller_software: ControllerText | None


@dataclass(frozen=True, slots=True)
class ControllerAlarm:
    """An alarm of a tool controller (Open Protocol MIDs 0071, 0074, 0076)."""

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    time_ns: TimeNs  # the controller's time of the alarm (its clock, station timezone)
    received_ns: TimeNs  # when the bridge received it
    error_code: ControllerText  # the controller's code, e.g. "E404"
    kind: AlarmKind
    active: bool  # the alarm is on (raised, or the status says so); False: it went off
    controller_ready: bool | None  # None: the message does not say
    tool_ready: bool | None
    text: str  # what the code means when known; "" otherwise


@dataclass(frozen=True, slots=True)
class BridgeStats:
    """A controller bridge's counters since its process started, once a second.

    A fault of the link or of a message is counted here, never fatal; ``boltwatch
    status`` shows the counters that are not zero.
    """

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    time_ns: TimeNs
    started_ns: TimeNs  # when this bridge process started: a new value, a new process
    controller: ControllerText  # "host:port" of the controller
    connected: bool  # the link is up (communication started, MID 0002 received)
    result_revision: Revision | None  # revision of MID 0061 in use; None: not subscribed yet
    connects: Count  # links started (0002 received)
    link_drops: Count  # links that ended: the controller dropped it, a read error, a timeout
    keep_alives_sent: Count  # MID 9999
    results: Count  # results published (0061, and 0065 when filling a gap)
    results_filled: Count  # of those, fetched with 0064 after a reconnect
    repeated_results: Count  # a tightening id already published: ignored, not counted twice
    traces: Count  # MID 0900 curves published as a run's samples
    traces_without_result: Count  # curves whose result never came
    garbage_bytes: Count  # bytes skipped looking for the next message
    bad_messages: Count  # wrong length, unparseable
    refused_values: Count  # a field out of its range: the message refused
    controller_errors: Count  # MID 0004 received
    last_tightening_id: Id | None
    last_error: str | None  # the newest fault, in one line; None: none since start
    # results published without their curves (0900 never came within the bridge's timeout)
    results_without_traces: Count = 0
    # curves refused: no time step, or samples that agree with their result read no way
    traces_refused: Count = 0
    # tightening ids the controller could not give (fetch failed or refused, too far back)
    results_given_up: Count = 0
    # the controller's ids started again (reset, replaced, wrapped): new run id epochs
    epochs: Count = 0
    # controller time stamps no clock holds (before 2000, a day ahead): replaced by arrival
    clock_refused: Count = 0
    # how the controller's 0900 samples read right ("big-endian, scaling as declared"); None:
    # not known yet
    trace_reading: ControllerText | None = None
    # the alarm active on the controller as the bridge last heard (0071, 0074, 0076); None:
    # none active, or not heard
    active_alarm: ControllerAlarm | None = None
