"""A line's alert as the state of an OPC UA condition, pure (no asyncua, no zenoh).

Each alert source is one condition (OPC 10000-9, 4.2) of its station's joining system,
identified by :attr:`ConditionState.key`:

- ``wear/<tool>``: a tool past its service threshold (:class:`~shared.contract.WearAlert`,
  put after every run until the tool is serviced); it goes off when the wear ledger shows
  the tool below its threshold again (:meth:`ConditionState.clear`, after a service);
- ``quality/<program>/<kind>``: a program's Cpk low, NOKs in a row, NOK rate
  (:class:`~shared.contract.QualityAlert`, on and off);
- ``alarm/<code>``: a controller's alarm (:class:`~shared.contract.ControllerAlarm`, on and
  off).

IJT's ``JoiningSystemConditionType`` is an ``AcknowledgeableConditionType`` (no
``ActiveState``: that is an alarm's); whether the alert is on is :attr:`active` here,
said by ``Retain``, the message and the condition class. The states, as node-opcua's
server and OPC 10000-9's examples (B.1) move them:

=========================  ======  =====  =========  ======
                           active  acked  confirmed  Retain
=========================  ======  =====  =========  ======
raised (was off)           yes     no     yes        yes
raised again while on      (unchanged: the message, severity and time are the new ones)
Acknowledge                        yes    no         yes
Confirm                                   yes        while active
went off                   no                        until acked and confirmed
=========================  ======  =====  =========  ======

``Retain`` is true while the alert is on, or not acknowledged, or not confirmed.
Acknowledge and Confirm take the EventId of one of the condition's notifications since it
was last raised (a client that acknowledges the notification it saw is not refused
because a newer one came meanwhile); another EventId is ``BadEventIdUnknown``; a second
acknowledge ``BadConditionBranchAlreadyAcked``, a second confirm
``BadConditionBranchAlreadyConfirmed``. AddComment sets the comment and its user.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import Literal, NamedTuple

#: how many notifications of a condition are remembered for Acknowledge and Confirm
EVENT_IDS_KEPT = 1000
Source = Literal["wear", "quality", "alarm"]
Action = Literal["acknowledged", "confirmed", "commented"]


class Said(NamedTuple):
    """What an alert said (the condition's message, severity, EventCode, class, time)."""

    time_ns: int
    message: str
    severity: int
    code: int
    condition_class: tuple[int, str]  # IJT Base's id and its name


class ConditionMethodError(ValueError):
    """A method refused: its OPC UA status code's name (``BadEventIdUnknown``...)."""

    def __init__(self, status: str) -> None:
        super().__init__(status)
        self.status = status


@dataclass
class ConditionState:
    """One alert source's condition and its current state (its trunk: no branches)."""

    key: str  # "wear/7", "quality/1/nok_run", "alarm/E404"
    source: Source
    name: str  # ConditionName
    active: bool = False
    acked: bool = True
    confirmed: bool = True
    severity: int = 0
    last_severity: int = 0
    message: str = ""
    code: int = 0  # JoiningSystemEventContent/EventCode
    condition_class: tuple[int, str] = (0, "")  # IJT Base's id and its name
    time_ns: int = 0  # when the alert last said something
    comment: str = ""
    client_user: str = ""  # who set the comment (acknowledged, confirmed, commented)
    #: the notifications since it was last raised (Acknowledge and Confirm take these)
    event_ids: deque[bytes] = field(default_factory=lambda: deque(maxlen=EVENT_IDS_KEPT))

    @property
    def retain(self) -> bool:
        return self.active or not self.acked or not self.confirmed

    def raised(self, said: Said) -> None:
        """The alert is on (again): a new occurrence when it was off."""
        if not self.active:
            self.active, self.acked, self.confirmed = True, False, True
            self.event_ids.clear()
        self._take(said)

    def cleared(self, said: Said) -> bool:
        """The alert went off; False when it was not on (nothing to report)."""
        if not self.active:
            return False
        self.active = False
        self._take(said)
        return True

    def _take(self, said: Said) -> None:
        self.last_severity = self.severity or said.severity
        self.time_ns, self.message, self.severity = said.time_ns, said.message, said.severity
        self.code, self.condition_class = said.code, said.condition_class

    def notified(self, event_id: bytes) -> None:
        """A notification of the current state went out with ``event_id``."""
        self.event_ids.append(event_id)

    def act(self, action: Action, event_id: bytes, comment: str, user: str) -> None:
        """Acknowledge, Confirm or AddComment; :class:`ConditionMethodError` when refused."""
        if event_id not in self.event_ids:
            raise ConditionMethodError("BadEventIdUnknown")
        if action == "acknowledged":
            if self.acked:
                raise ConditionMethodError("BadConditionBranchAlreadyAcked")
            self.acked, self.confirmed = True, False
        elif action == "confirmed":
            if self.confirmed:
                raise ConditionMethodError("BadConditionBranchAlreadyConfirmed")
            self.confirmed = True
        self.comment, self.client_user = comment, user
