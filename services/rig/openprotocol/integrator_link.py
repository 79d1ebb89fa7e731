"""One integrator's session with the simulated controller: frames in, wire bytes out.

No sockets here (:mod:`.controller_server` owns them): :meth:`IntegratorLink.receive`
takes what a read returned (any split: the codec's ``FrameReader`` keeps a
partial message), :meth:`~IntegratorLink.tightening` a finished tightening,
:meth:`~IntegratorLink.tick` the time; what is to be sent collects in
:meth:`~IntegratorLink.take_output`, and :attr:`~IntegratorLink.closed` says
why the link must end (then every subscription ends with it).

What it answers, as real controllers do:

- 0001 -> 0002 at the revision asked when the codec has it, else 0004 error
  97; a second 0001 on a started link -> 0004 error 96. Before 0001 nothing
  but 0001 is answered (a controller's session starts there).
- 0060 / 0008 (of MID 0900) / 0070 -> 0005, or 0004: 97 (revision), 9 / 71 /
  11 (already subscribed), 73 (0008 of a MID other than 0900), 74 (0900 at a
  revision the codec lacks); 0063 / 0009 / 0073 -> 0005 or 0004 10 / 72 / 12.
  The 0005 of a 0008 / 0009 names the MID subscribed for (0900), as the
  specification words it ("MID 0005 Command accepted with the MID subscribed
  for"); the 0004 of a refused one names 0008 / 0009.
  After 0070 the alarm status (0076) follows.
- 0061 pushed to a result subscriber, one at a time: the next waits for the
  0062 of the one before (queued, newest last, never more than the store
  keeps). Not acknowledged within ``ack_timeout_s``: sent again, at most
  ``result_resends`` times; then the link is dropped. 0900 (torque, then
  angle) pushed to a 0900 subscriber with each tightening, not re-sent (its
  0005 is taken, not waited for).
- 0064 -> 0065 of the id asked (0: the newest), or 0004 error 15 when the id
  is not kept; 0040 -> 0041; 9999 -> 9999 when mirroring (a setting).
- A multi-spindle system's: 0090 / 0100 -> 0005, or 0004: 30 (a controller of
  one spindle: no sync master), 31 / 33 (already subscribed), 97; 0093 /
  0103 -> 0005 or 0004 32 / 34. After each cycle 0091 and 0101 (at the
  revision subscribed) are pushed to their subscribers; their acknowledges
  (0092, 0102) are taken as receipts, nothing is sent again.
- 0003 -> 0005, then the link ends. Any other MID -> 0004 error 99; content
  the codec refuses -> 0004 error 1 (invalid data), counted.
- Nothing heard for ``link_timeout_s``: the link is dropped.
"""

from __future__ import annotations

import logging
from collections import deque
from dataclasses import dataclass

from services.rig.openprotocol.controller_counters import ControllerCounters
from services.rig.openprotocol.controller_state import ControllerState
from services.rig.openprotocol.tightening import Tightening
from shared.openprotocol import (
    KNOWN_MIDS,
    AlarmAcknowledge,
    AlarmAcknowledgedOnControllerAck,
    AlarmStatusAck,
    AlarmSubscribe,
    AlarmUnsubscribe,
    CommandAccepted,
    CommandError,
    CommunicationStart,
    CommunicationStop,
    DataSubscribe,
    DataUnsubscribe,
    ErrorCode,
    Frame,
    FrameReader,
    KeepAlive,
    MultiSpindleResultAcknowledge,
    MultiSpindleResultSubscribe,
    MultiSpindleResultUnsubscribe,
    MultiSpindleStatusAcknowledge,
    MultiSpindleStatusSubscribe,
    MultiSpindleStatusUnsubscribe,
    OldResultRequest,
    OpenProtocolError,
    ResultAcknowledge,
    ResultSubscribe,
    ResultUnsubscribe,
    ToolDataRequest,
    WireMessage,
    decode,
    trace_types_of,
)

LOG = logging.getLogger(__name__)

TRACE_MID = 900
#: the curves the simulated tool has (0900 trace types): angle, torque
TRACE_TYPES = (1, 2)
#: the integrator's receipts: of a 0900 (0005 "0900"), of alarm messages (0072, 0075, 0077)
RECEIPTS = (
    CommandAccepted,
    AlarmAcknowledge,
    AlarmAcknowledgedOnControllerAck,
    AlarmStatusAck,
    MultiSpindleStatusAcknowledge,
    MultiSpindleResultAcknowledge,
)


@dataclass
class _Pending:
    """A 0061 awaiting its 0062."""

    tightening_id: int
    wire: bytes
    sends: int
    sent_at: float


class IntegratorLink:
    """The session of one connected integrator."""

    def __init__(self, peer: str, state: ControllerState, now: float) -> None:
        self.peer = peer
        self._state = state
        self._counters: ControllerCounters = state.counters
        self._settings = state.settings
        self._reader = FrameReader(known_mids=KNOWN_MIDS)
        self._output = bytearray()
        self._heard_at = now
        self.started = False
        self.result_revision: int | None = None
        self.trace_revision: int | None = None
        self.trace_types: tuple[int, ...] = ()
        self.alarm_revision: int | None = None
        self.cycle_status_subscribed = False
        self.cycle_result_revision: int | None = None
        self._queue: deque[Tightening] = deque(maxlen=self._settings.results_kept)
        self._pending: _Pending | None = None
        #: why the link must end (None: it goes on)
        self.closed: str | None = None

    # -- what the server asks ------------------------------------------------------------

    def take_output(self) -> bytes:
        data = bytes(self._output)
        self._output.clear()
        return data

    @property
    def outstanding(self) -> int:
        """Results pushed or queued and not yet acknowledged."""
        return len(self._queue) + (self._pending is not None)

    def deadline(self) -> float:
        """When :meth:`tick` has something to do at the latest."""
        silent_at = self._heard_at + self._settings.link_timeout_s
        if self._pending is None:
            return silent_at
        return min(silent_at, self._pending.sent_at + self._settings.ack_timeout_s)

    def tick(self, now: float) -> None:
        if self.closed is not None:
            return
        if now - self._heard_at >= self._settings.link_timeout_s:
            self._close("silent", f"nothing heard for {self._settings.link_timeout_s:g} s")
            self._counters.drops_silent += 1
            return
        pending = self._pending
        if pending is None or now - pending.sent_at < self._settings.ack_timeout_s:
            return
        if pending.sends > self._settings.result_resends:
            self._close(
                "ack",
                f"result {pending.tightening_id} not acknowledged after "
                f"{self._settings.result_resends} re-sends",
            )
            self._counters.drops_ack += 1
            return
        pending.sends += 1
        pending.sent_at = now
        self._output += pending.wire
        self._counters.results_resent += 1
        LOG.info("%s: result %d sent again (%d)", self.peer, pending.tightening_id, pending.sends)

    def receive(self, chunk: bytes, now: float) -> None:
        garbage, bad = self._reader.garbage_bytes, self._reader.bad_frames
        frames = self._reader.feed(chunk)
        self._counters.garbage_bytes += self._reader.garbage_bytes - garbage
        self._counters.bad_frames += self._reader.bad_frames - bad
        if frames or chunk:
            self._heard_at = now
        for frame in frames:
            if self.closed is not None:
                return
            self._handle(frame, now)

    def tightening(self, tightening: Tightening, now: float) -> None:
        """A finished tightening: pushed to what this integrator subscribed to."""
        if self.closed is not None:
            return
        if self.trace_revision is not None:
            for message in self._state.traces(tightening, self.trace_types):
                self._send(message, self.trace_revision)
                self._counters.traces_pushed += 1
        if self.result_revision is not None:
            self._queue.append(tightening)
            self._push_next(now)

    def cycle(self, cycle: list[Tightening]) -> None:
        """A multi-spindle system's cycle, after its spindles' tightenings: its status and its
        result to their subscribers."""
        if self.closed is not None:
            return
        if self.cycle_status_subscribed:
            self._send(self._state.cycle_status(cycle))
        if self.cycle_result_revision is not None:
            revision = self.cycle_result_revision
            self._send(self._state.cycle_result(cycle, revision), revision)

    def alarm_message(self, message: WireMessage) -> None:
        """An alarm raised (0071) or cleared (0074): sent to an alarm subscriber."""
        if self.closed is None and self.alarm_revision is not None:
            revision = min(self.alarm_revision, self._state.highest_revision(message.MID))
            self._send(message, revision)

    # -- what the integrator says --------------------------------------------------------

    def _handle(self, frame: Frame, now: float) -> None:
        if not self.started and frame.mid != CommunicationStart.MID:
            LOG.debug("%s: MID %04d before 0001: ignored", self.peer, frame.mid)
            return
        if frame.revision > self._state.highest_revision(frame.mid):
            if self._state.knows(frame.mid):
                self._refuse(frame.mid, ErrorCode.MID_REVISION_UNSUPPORTED)
            else:
                self._refuse(frame.mid, ErrorCode.UNKNOWN_MID)
            return
        try:
            message = decode(frame)
        except OpenProtocolError as err:
            self._counters.bad_messages += 1
            LOG.warning("%s: %s", self.peer, err)
            self._refuse(frame.mid, ErrorCode.INVALID_DATA)
            return
        self._answer(message, frame, now)

    def _answer(self, message: object, frame: Frame, now: float) -> None:
        """One message the integrator sent, by its exact type (0009 is a kind of 0008)."""
        handlers = {
            CommunicationStart: self._start,
            CommunicationStop: self._stop,
            KeepAlive: self._keep_alive,
            ResultSubscribe: self._subscribe_results,
            ResultUnsubscribe: self._unsubscribe_results,
            ResultAcknowledge: self._acknowledged,
            OldResultRequest: self._old_result,
            DataSubscribe: self._subscribe_data,
            DataUnsubscribe: self._unsubscribe_data,
            ToolDataRequest: self._tool_data,
            AlarmSubscribe: self._subscribe_alarms,
            AlarmUnsubscribe: self._unsubscribe_alarms,
            MultiSpindleStatusSubscribe: self._subscribe_cycles,
            MultiSpindleStatusUnsubscribe: self._unsubscribe_cycles,
            MultiSpindleResultSubscribe: self._subscribe_cycles,
            MultiSpindleResultUnsubscribe: self._unsubscribe_cycles,
        }
        handler = handlers.get(type(message))
        if handler is not None:
            handler(message, frame, now)
        elif not isinstance(message, RECEIPTS):  # receipts are taken: nothing waits for them
            self._refuse(frame.mid, ErrorCode.UNKNOWN_MID)

    def _start(self, _message: object, frame: Frame, _now: float) -> None:
        if self.started:
            self._refuse(frame.mid, ErrorCode.CLIENT_ALREADY_CONNECTED)
            return
        self.started = True
        self._send(self._state.start_ack(frame.revision))

    def _stop(self, _message: object, frame: Frame, _now: float) -> None:
        self._accept(frame.mid)
        self._close("stopped", "the integrator stopped the session (0003)")
        self._counters.drops_stopped += 1

    def _keep_alive(self, _message: object, _frame: Frame, _now: float) -> None:
        self._counters.keep_alives += 1
        if self._settings.mirror_keep_alive:
            self._send(KeepAlive())

    def _unsubscribe_results(self, _message: object, frame: Frame, _now: float) -> None:
        if self.result_revision is None:
            self._refuse(frame.mid, ErrorCode.LAST_TIGHTENING_SUBSCRIPTION_MISSING)
            return
        self.result_revision = None
        self._queue.clear()
        self._pending = None
        self._accept(frame.mid)

    def _unsubscribe_data(self, message: object, frame: Frame, _now: float) -> None:
        assert isinstance(message, DataUnsubscribe)
        if message.mid != TRACE_MID or self.trace_revision is None:
            self._refuse(frame.mid, ErrorCode.SUBSCRIPTION_MISSING)
            return
        self.trace_revision = None
        self._accept(message.mid)  # "accepted with the MID subscribed for", as for 0008

    def _tool_data(self, _message: object, frame: Frame, _now: float) -> None:
        self._send(self._state.tool_data(frame.revision))

    def _subscribe_alarms(self, _message: object, frame: Frame, _now: float) -> None:
        if self.alarm_revision is not None:
            self._refuse(frame.mid, ErrorCode.ALARM_SUBSCRIPTION_EXISTS)
            return
        self.alarm_revision = frame.revision
        self._accept(frame.mid)
        self._send(self._state.alarm_status(frame.revision))

    def _unsubscribe_alarms(self, _message: object, frame: Frame, _now: float) -> None:
        if self.alarm_revision is None:
            self._refuse(frame.mid, ErrorCode.ALARM_SUBSCRIPTION_MISSING)
            return
        self.alarm_revision = None
        self._accept(frame.mid)

    def _subscribe_cycles(self, message: object, frame: Frame, _now: float) -> None:
        """0090 or 0100: a multi-spindle system's cycles (a single tool is no sync master)."""
        status = isinstance(message, MultiSpindleStatusSubscribe)
        if self._state.spindles < 2:
            self._refuse(frame.mid, ErrorCode.NOT_A_SYNC_MASTER)
        elif self.cycle_status_subscribed if status else self.cycle_result_revision is not None:
            exists = ErrorCode.MULTI_SPINDLE_STATUS_SUBSCRIPTION_EXISTS
            self._refuse(
                frame.mid, exists if status else ErrorCode.MULTI_SPINDLE_RESULT_SUBSCRIPTION_EXISTS
            )
        else:
            if status:
                self.cycle_status_subscribed = True
            else:
                self.cycle_result_revision = frame.revision
            self._accept(frame.mid)

    def _unsubscribe_cycles(self, message: object, frame: Frame, _now: float) -> None:
        status = isinstance(message, MultiSpindleStatusUnsubscribe)
        if not (self.cycle_status_subscribed if status else self.cycle_result_revision):
            missing = ErrorCode.MULTI_SPINDLE_STATUS_SUBSCRIPTION_MISSING
            self._refuse(
                frame.mid,
                missing if status else ErrorCode.MULTI_SPINDLE_RESULT_SUBSCRIPTION_MISSING,
            )
            return
        if status:
            self.cycle_status_subscribed = False
        else:
            self.cycle_result_revision = None
        self._accept(frame.mid)

    def _subscribe_results(self, _message: object, frame: Frame, _now: float) -> None:
        if self.result_revision is not None:
            self._refuse(frame.mid, ErrorCode.LAST_TIGHTENING_SUBSCRIPTION_EXISTS)
            return
        self.result_revision = frame.revision
        self._accept(frame.mid)
        self._state.result_subscriber.set()

    def _subscribe_data(self, message: object, frame: Frame, _now: float) -> None:
        assert isinstance(message, DataSubscribe)
        if message.mid != TRACE_MID:
            self._refuse(frame.mid, ErrorCode.SUBSCRIBED_MID_UNSUPPORTED)
            return
        if message.wanted_revision > self._state.highest_revision(TRACE_MID):
            self._refuse(frame.mid, ErrorCode.SUBSCRIBED_MID_REVISION_UNSUPPORTED)
            return
        if self.trace_revision is not None:
            self._refuse(frame.mid, ErrorCode.SUBSCRIPTION_EXISTS)
            return
        try:
            asked = trace_types_of(message.extra_data) if message.extra_data else TRACE_TYPES
        except OpenProtocolError as err:
            self._counters.bad_messages += 1
            LOG.warning("%s: %s", self.peer, err)
            self._refuse(frame.mid, ErrorCode.INVALID_DATA)
            return
        self.trace_revision = message.wanted_revision
        self.trace_types = tuple(kind for kind in asked if kind in TRACE_TYPES)
        self._accept(message.mid)  # the specification: "accepted with the MID subscribed for"

    def _old_result(self, message: object, frame: Frame, _now: float) -> None:
        assert isinstance(message, OldResultRequest)
        tightening = self._state.store.find(message.tightening_id)
        if tightening is None:
            self._refuse(frame.mid, ErrorCode.TIGHTENING_ID_NOT_FOUND)
            return
        self._send(self._state.old_result(tightening, frame.revision), frame.revision)
        self._counters.old_results_served += 1
        self._state.delivered(tightening.tightening_id)

    def _acknowledged(self, _message: object, _frame: Frame, now: float) -> None:
        if self._pending is None:
            LOG.debug("%s: 0062 with no result awaiting it", self.peer)
            return
        self._state.delivered(self._pending.tightening_id)
        self._pending = None
        self._counters.results_acked += 1
        self._push_next(now)

    # -- what the controller says --------------------------------------------------------

    def _push_next(self, now: float) -> None:
        if self._pending is not None or not self._queue or self.result_revision is None:
            return
        tightening = self._queue.popleft()
        result = self._state.result(tightening, self.result_revision)
        wire = self._state.wire(result, self.result_revision)
        self._pending = _Pending(tightening.tightening_id, wire, sends=1, sent_at=now)
        self._output += wire
        self._counters.results_pushed += 1

    def _send(self, message: WireMessage, revision: int | None = None) -> None:
        self._output += self._state.wire(message, revision)

    def _accept(self, mid: int) -> None:
        self._send(CommandAccepted(mid=mid))

    def _refuse(self, mid: int, code: ErrorCode) -> None:
        self._send(CommandError(mid=mid, error_code=int(code)))
        self._counters.errors_sent += 1
        LOG.info("%s: MID %04d refused: %s (%d)", self.peer, mid, code.name, code)

    def _close(self, kind: str, why: str) -> None:
        self.closed = kind
        LOG.info("%s: link dropped: %s", self.peer, why)
