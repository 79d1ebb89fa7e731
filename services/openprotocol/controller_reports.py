"""What a controller says besides its tightenings: its tool (0041) and its alarms (0071-0076).

- tool data: asked (0040, at the highest revision the controller answers: rev
  2 carries the count since service, the tool type) after every connect, after
  each tightening and every minute (a recorder that was not listening at the
  connect gets it); the 0041 becomes boltwatch's
  :class:`~shared.contract.messages.ToolData` on ``tool_data`` (the station file's tool
  id, the controller's serials, counters, calibration and service dates), which
  the wear ledger keeps beside the station's tool;
- alarms: subscribed (0070) after every connect; 0071 (raised), 0074
  (acknowledged on the controller) and 0076 (the alarm status, sent on
  subscription) each become a :class:`~shared.contract.messages.ControllerAlarm` on
  ``alarms`` and are acknowledged (0072, 0075, 0077) at once. The alarm active
  now (the last 0071 or active 0076, until a 0074 of its code or an inactive
  0076) is kept in the bridge's counters, so ``status`` knows it whenever it
  asks, not only when it heard the alarm.

A date the controller gives that no clock holds is left out (None) and
counted as a refused value, never a refused message.
"""

from __future__ import annotations

import time
import zoneinfo
from collections.abc import Callable
from typing import Any

from services.openprotocol.bridge_counts import BridgeCounts
from shared.contract import ControllerAlarm
from shared.contract import ToolData as LineToolData
from shared.openprotocol import (
    SUPPORTED_REVISIONS,
    Alarm,
    AlarmAcknowledge,
    AlarmAcknowledgedOnController,
    AlarmAcknowledgedOnControllerAck,
    AlarmStatus,
    AlarmStatusAck,
    AlarmSubscribe,
    ToolDataRequest,
    timestamp_ns,
)
from shared.openprotocol import ToolData as ControllerToolData

TOOL_DATA_MID = 41
#: the highest revisions asked: 0070 (0071 at rev 2 carries the alarm's text), 0040
HIGHEST_ALARMS = max(SUPPORTED_REVISIONS[AlarmSubscribe.MID])
HIGHEST_TOOL = max(SUPPORTED_REVISIONS[ToolDataRequest.MID])


class ControllerReports:
    """Tool data and alarms of one station's controller."""

    def __init__(self, station: str, tool_id: int, timezone: str = "UTC") -> None:
        self._station = station
        self._tool_id = tool_id
        self._zone = zoneinfo.ZoneInfo(timezone)
        self._tool_data_revision = 1

    def subscribe(
        self, session: Any, publish: Callable[[object], None], counts: BridgeCounts
    ) -> None:
        """0070 (alarms) and 0040 (tool data, at the highest revision the controller
        answers) after a session started."""
        counts.active_alarm = None  # the 0076 that answers 0070 says it again
        session.subscribe(lambda revision: AlarmSubscribe(revision=revision), HIGHEST_ALARMS)
        self._tool_data_revision, reply = session.request_highest(
            lambda revision: ToolDataRequest(revision=revision), {TOOL_DATA_MID}, HIGHEST_TOOL
        )
        if isinstance(reply, ControllerToolData):
            publish(self.tool_data(reply, time.time_ns(), counts))

    def ask_tool_data(self, session: Any) -> None:
        """0040 without waiting: the 0041 comes as a pushed message (:meth:`pushed`)."""
        session.send(ToolDataRequest(revision=self._tool_data_revision))

    def pushed(
        self,
        message: Any,
        session: Any,
        publish: Callable[[object], None],
        counts: BridgeCounts,
    ) -> None:
        """Handle a pushed message that is not a result or a curve."""
        now_ns = time.time_ns()
        if isinstance(message, ControllerToolData):
            publish(self.tool_data(message, now_ns, counts))
        elif isinstance(message, Alarm):
            session.send(AlarmAcknowledge())
            alarm = self._alarm(message, "raised", True, message.alarm_text or "", now_ns, counts)
            counts.active_alarm = alarm
            publish(alarm)
        elif isinstance(message, AlarmAcknowledgedOnController):
            session.send(AlarmAcknowledgedOnControllerAck())
            code = message.error_code.strip()
            active = counts.active_alarm
            if active is not None and active.error_code == code:
                counts.active_alarm = None
            publish(
                ControllerAlarm(
                    station=self._station,
                    time_ns=now_ns,
                    received_ns=now_ns,
                    error_code=code,
                    kind="acknowledged",
                    active=False,
                    controller_ready=None,
                    tool_ready=None,
                    text="",
                )
            )
        elif isinstance(message, AlarmStatus):
            session.send(AlarmStatusAck())
            alarm = self._alarm(message, "status", message.alarm_active, "", now_ns, counts)
            counts.active_alarm = alarm if alarm.active else None
            publish(alarm)
        else:
            counts.fault("bad message", f"MID {getattr(message, 'MID', '?')} not expected: ignored")

    def tool_data(self, message: ControllerToolData, now_ns: int, counts: BridgeCounts) -> Any:
        return LineToolData(
            station=self._station,
            tool_id=self._tool_id,
            time_ns=now_ns,
            tool_serial=message.tool_serial.strip(),
            controller_serial=(message.controller_serial or "").strip() or None,
            tightenings=message.tightenings,
            tightenings_since_service=message.tightenings_since_service,
            last_calibration_ns=self._date(message.last_calibration, counts),
            last_service_ns=self._date(message.last_service, counts),
            calibration_value_nm=message.calibration_value_nm,
            tool_type=None if message.tool_type is None else str(message.tool_type),
            tool_model=(message.tool_model or "").strip() or None,
            controller_software=(message.controller_software_version or "").strip() or None,
        )

    def _alarm(
        self, message: Any, kind: str, active: bool, text: str, now_ns: int, counts: BridgeCounts
    ) -> ControllerAlarm:
        return ControllerAlarm(
            station=self._station,
            time_ns=self._date(message.time, counts) or now_ns,
            received_ns=now_ns,
            error_code=message.error_code.strip(),
            kind=kind,  # type: ignore[arg-type]
            active=bool(active),
            controller_ready=bool(message.controller_ready),
            tool_ready=bool(message.tool_ready),
            text=text.strip(),
        )

    def _date(self, text: str | None, counts: BridgeCounts) -> int | None:
        if text is None or not text.strip() or set(text.strip()) <= {"0", "-", ":"}:
            return None
        try:
            value = timestamp_ns(text, self._zone)
        except ValueError as err:
            counts.refused_values += 1
            counts.fault("refused value", f"a controller date left out: {err}")
            return None
        return value if value >= 0 else None
