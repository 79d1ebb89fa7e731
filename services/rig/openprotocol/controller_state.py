"""What the simulated controller holds across links: results, alarm, tool, how it writes.

One :class:`ControllerState` per controller, used by the serving thread only
(:mod:`.controller_server`): every :class:`~.integrator_link.IntegratorLink`
reads its settings and writes through it.

- the results (:class:`~.result_store.ResultStore`, bounded) and the counters;
- how it writes: the station's ``[openprotocol]`` header fill and 0900 byte
  order (the codec's :class:`~shared.openprotocol.dialect.Dialect`) and time
  zone (its time stamps are local time there);
- the revisions it speaks: what the codec implements
  (:data:`~shared.openprotocol.codec.SUPPORTED_REVISIONS`), 0061/0064/0065
  up to ``max_result_revision``;
- a multi-spindle system (``spindles`` above 1): each cycle's status (0091) and
  result (0101, :mod:`.cycle_messages`);
- the alarm: a run that ends on a hard limit raises one (0071, codes below,
  the simulated controller's own: real controllers have their own tables);
  it stays active until the next run that ends without a limit, which clears
  it (0074, "acknowledged on the controller"); 0076 after each 0070 says
  whether one is active;
- tool data (0041, revisions 1 to 5): serial ``SIM-<tool id>``, the
  tightenings of this controller process (also the count since service), the
  configured last calibration and service dates (default: the day the
  controller started), calibration value and max torque = the program's hard
  torque limit, full speed = its motor speed, model ``BW-SIM``.
"""

from __future__ import annotations

import datetime as dt
import logging
import math
import threading
import zoneinfo

from services.rig.controller import StopSource
from services.rig.openprotocol.controller_counters import ControllerCounters
from services.rig.openprotocol.cycle_messages import cycle_result, cycle_status
from services.rig.openprotocol.result_messages import (
    ControllerIdentity,
    last_result,
    old_result,
    trace_curves,
)
from services.rig.openprotocol.result_store import ResultStore
from services.rig.openprotocol.tightening import Tightening
from shared.config import OpenProtocolSection, Program, RigOpenProtocolSection
from shared.openprotocol import (
    ANY_REVISION_MIDS,
    HIGHEST_REVISION,
    SUPPORTED_REVISIONS,
    Alarm,
    AlarmAcknowledgedOnController,
    AlarmStatus,
    CommunicationStartAck,
    Dialect,
    ToolData,
    TraceCurve,
    WireMessage,
    encode,
)

LOG = logging.getLogger(__name__)

#: the MIDs whose revision is the 0061/0065 revision (capped by max_result_revision)
RESULT_MIDS = frozenset({60, 61, 64, 65})
#: the simulated controller's alarm codes: a run that ended on a hard limit
ALARM_CODES: dict[StopSource, tuple[str, str]] = {
    StopSource.LIMIT_TORQUE: ("E101", "torque limit reached: tool stopped"),
    StopSource.LIMIT_FORCE: ("E102", "force limit reached: tool stopped"),
    StopSource.LIMIT_ANGLE: ("E103", "angle limit reached: tool stopped"),
    StopSource.LIMIT_TIME: ("E104", "cycle time limit reached: tool stopped"),
}
SUPPLIER_CODE = "BWS"
SOFTWARE_VERSION = "boltwatch-sim 1"
TOOL_MODEL = "BW-SIM"


class ControllerState:
    """The controller's results, alarm, identity and writing settings."""

    def __init__(
        self,
        station_id: str,
        tool_id: int,
        program: Program,
        section: OpenProtocolSection,
        settings: RigOpenProtocolSection,
        *,
        started: dt.date | None = None,
        spindles: int = 1,
    ) -> None:
        """``spindles``: above 1, a multi-spindle system (a sync master: it takes the
        multi-spindle subscriptions, 0090 and 0100)."""
        self.settings = settings
        self.spindles = spindles
        self.counters = ControllerCounters()
        self.store = ResultStore(settings.results_kept)
        self.identity = ControllerIdentity(station_id, tool_id, zoneinfo.ZoneInfo(section.timezone))
        self.dialect = Dialect(
            header_fill="space" if section.header_fill == "spaces" else "zero",
            trace_byte_order="little" if section.trace_byte_order == "little" else "big",
        )
        self._program = program
        started = started or dt.date.today()
        self._last_calibration = settings.last_calibration or started
        self._last_service = settings.last_service or started
        #: the active alarm's (code, text, time_ns), None when no alarm is active
        self.alarm: tuple[str, str, int] | None = None
        #: set when an integrator first subscribes to results (``--wait-for-integrator``)
        self.result_subscriber = threading.Event()
        #: tightening ids no integrator has had yet (acknowledged 0061 or served 0065)
        self._undelivered: set[int] = set()

    # -- revisions ---------------------------------------------------------------------

    def knows(self, mid: int) -> bool:
        return mid in SUPPORTED_REVISIONS

    def highest_revision(self, mid: int) -> int:
        """The highest revision of ``mid`` the controller answers (0: an MID it does not know)."""
        if mid in ANY_REVISION_MIDS:  # an acknowledge, 0003, 9999: no data at any revision
            return HIGHEST_REVISION
        revisions = SUPPORTED_REVISIONS.get(mid, ())
        highest = max(revisions, default=0)
        if mid in RESULT_MIDS:
            highest = min(highest, self.settings.max_result_revision)
        return highest

    # -- what it writes ----------------------------------------------------------------

    def wire(self, message: WireMessage, revision: int | None = None) -> bytes:
        """``message`` on the wire at ``revision`` (default: its own)."""
        return encode(message, revision=revision, dialect=self.dialect)

    def start_ack(self, revision: int) -> CommunicationStartAck:
        identity = self.identity
        return CommunicationStartAck(
            cell_id=identity.cell_id,
            channel_id=identity.channel_id,
            controller_name=identity.controller_name,
            supplier_code=SUPPLIER_CODE if revision >= 2 else None,
            open_protocol_version="2.8.0" if revision >= 3 else None,
            controller_software_version=SOFTWARE_VERSION if revision >= 3 else None,
            tool_software_version=SOFTWARE_VERSION if revision >= 3 else None,
            revision=revision,
        )

    def result(self, tightening: Tightening, revision: int) -> WireMessage:
        return last_result(tightening, revision, self.identity)

    def old_result(self, tightening: Tightening, revision: int) -> WireMessage:
        return old_result(tightening, revision, self.identity)

    def cycle_result(self, cycle: list[Tightening], revision: int) -> WireMessage:
        return cycle_result(cycle, revision, self.identity)

    def cycle_status(self, cycle: list[Tightening]) -> WireMessage:
        return cycle_status(cycle, self.identity)

    def traces(self, tightening: Tightening, trace_types: tuple[int, ...]) -> list[TraceCurve]:
        return trace_curves(tightening, trace_types, self.identity)

    def tool_data(self, revision: int) -> ToolData:
        identity = self.identity
        second = revision >= 2
        return ToolData(
            tool_serial=identity.tool_serial,
            tightenings=self.counters.tightenings,
            last_calibration=_date_text(self._last_calibration),
            controller_serial=identity.controller_serial,
            calibration_value_nm=self._program.max_torque_nm if second else None,
            last_service=_date_text(self._last_service) if second else None,
            tightenings_since_service=self.counters.tightenings if second else None,
            tool_type=1 if second else None,
            motor_size=0 if second else None,
            open_end_data="000" if second else None,
            controller_software_version=SOFTWARE_VERSION if second else None,
            max_torque_nm=self._program.max_torque_nm if revision >= 3 else None,
            gear_ratio=1.0 if revision >= 3 else None,
            full_speed_rpm=self._full_speed_rpm() if revision >= 3 else None,
            primary_tool=1 if revision >= 4 else None,
            tool_model=TOOL_MODEL if revision >= 5 else None,
            revision=revision,
        )

    def _full_speed_rpm(self) -> float:
        """The program's motor speed (rad/s) in revolutions a minute, as 0041 rev 3 has it."""
        return round(self._program.motor_speed_rad_s * 60.0 / (2.0 * math.pi), 2)

    def alarm_status(self, revision: int) -> AlarmStatus:
        alarm = self.alarm
        return AlarmStatus(
            alarm_active=alarm is not None,
            error_code=alarm[0] if alarm is not None else "",
            controller_ready=True,
            tool_ready=True,
            time=self.identity.timestamp(alarm[2] if alarm is not None else 0),
            revision=revision,
        )

    # -- what happens ------------------------------------------------------------------

    def delivered(self, tightening_id: int) -> None:
        """An integrator has the result ``tightening_id`` (it acknowledged it, or was served it)."""
        self._undelivered.discard(tightening_id)

    def undelivered(self) -> int:
        """How many kept tightenings no integrator has had yet."""
        self._undelivered = {i for i in self._undelivered if self.store.find(i) is not None}
        return len(self._undelivered)

    def tightening(self, tightening: Tightening) -> list[WireMessage]:
        """A finished tightening: kept and counted; the alarm messages it raises or clears
        (for alarm subscribers: each link writes them at the revision it subscribed)."""
        self.store.add(tightening)
        self._undelivered.add(tightening.tightening_id)
        counters = self.counters
        counters.tightenings += 1
        counters.ok += tightening.ok
        counters.nok += not tightening.ok
        LOG.info(
            "tightening %d: %s, %.1f Nm, %d deg, stopped by %s, batch %d/%d; %s",
            tightening.tightening_id,
            "OK" if tightening.ok else "NOK",
            tightening.final_torque_nm,
            round(tightening.final_angle_deg),
            tightening.curves.stop_source,
            tightening.batch_counter,
            tightening.batch_size,
            counters.line(),
        )
        code = ALARM_CODES.get(tightening.curves.stop_source)
        if code is not None:
            self.alarm = (code[0], code[1], tightening.ended_ns)
            counters.alarms += 1
            LOG.warning("alarm %s: %s (tightening %d)", *code, tightening.tightening_id)
            return [
                Alarm(
                    error_code=code[0],
                    controller_ready=True,
                    tool_ready=True,
                    time=self.identity.timestamp(tightening.ended_ns),
                    alarm_text=code[1],
                )
            ]
        if self.alarm is not None:
            cleared, self.alarm = self.alarm[0], None
            return [AlarmAcknowledgedOnController(error_code=cleared)]
        return []


def _date_text(day: dt.date) -> str:
    return f"{day.isoformat()}:00:00:00"
