"""What the line says of the handling of its alerts: who acknowledged one, and when.

Re-exported by :mod:`shared.contract.messages`. Same rules as every message
there. The line's alerts (a tool's wear, a program's quality, a controller's
alarm) are conditions of the station's joining system on the line's OPC UA
server; when a client (a SCADA, an HMI) acknowledges, confirms or comments on
one, the server puts an :class:`AlertAck` on ``boltwatch/<st>/alert/ack``, and
the line's recorder records it beside the alerts, so whoever reads the
recordings sees who took note of which alert, and when.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Literal

from shared.contract.message_fields import WIRE_CONFIG, StationId, TextRange, TimeNs

#: the alert's kind: ``wear`` (a tool's, ``wear/alert``), ``quality`` (a program's,
#: ``quality/alert``), ``alarm`` (a controller's, ``alarms``)
AlertSource = Literal["wear", "quality", "alarm"]
#: what was done: OPC UA's Acknowledge, Confirm and AddComment
AlertAction = Literal["acknowledged", "confirmed", "commented"]
#: a condition's key (``wear/7``, ``quality/1/nok_run``, ``alarm/E404``) or name
ConditionText = Annotated[str, TextRange(200)]
#: who: an OPC UA user name, a client's application URI
ClientText = Annotated[str, TextRange(400)]


@dataclass(frozen=True, slots=True)
class AlertAck:
    """A person (through an OPC UA client) acknowledged, confirmed or commented on an alert."""

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    time_ns: TimeNs  # when the server did it
    action: AlertAction
    source: AlertSource
    condition: ConditionText  # its key: wear/<tool>, quality/<program>/<kind>, alarm/<code>
    condition_name: ConditionText  # its ConditionName, as the client showed it
    alert_time_ns: TimeNs  # when the alert last said something (the condition's Time)
    active: bool  # the alert was still on
    user: ClientText  # the session's user name ("" for an anonymous session)
    client: ClientText  # the client's application URI ("" when it gave none)
    comment: str  # the client's comment ("" for none)
