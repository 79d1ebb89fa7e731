"""A tightening controller speaking Open Protocol on 127.0.0.1, for testing integrators.

Written from the Open Protocol Specification R2.8.0 (Atlas Copco 9836 4415 01), checked
against R2.16.0 and public implementations (see each layout module), never from
boltwatch's own codec. The behaviour, by section:

- 2.1.1 / 3.3.1: the controller is the TCP server; one integrator at a time (a second
  connection waits in the listen backlog until the first link ends).
- 3.1 / 5.2.1: MID 0001 first; "The controller does not respond to any other command before
  this" (what comes before is not answered). MID 0002 at the header's revision, or MID 0004
  error 97 above `max_start_revision`; a second MID 0001 on a started link: error 96.
- 5.2.3: MID 0003 answered by MID 0005, then the link ends.
- 5.8: MID 0060 subscribes to MID 0061 at its header revision (error 9 if subscribed, 97
  above `max_result_revision`); MID 0063 unsubscribes (error 10). MID 0064 asks for a kept
  result (id 0 = the newest) at its header revision: MID 0065, or error 15 / 97.
- 4.3.3: a pushed MID 0061 must be acknowledged (MID 0062, or MID 0005 naming 0061) within
  `ack_timeout_s`, else it is re-sent, `resends` times at most, then the link is considered
  lost. Results wait in a queue and go one at a time, unless the subscription had the no
  ack flag (2.2.2), then each goes at once and waits for nothing.
- 5.10: MID 0070 (header revision = MID 0071/0076 revision) is answered by MID 0005 and at
  once MID 0076 with the current alarm; a raised alarm is pushed as MID 0071, one
  acknowledged on the controller as MID 0074. MID 0072/0075/0077 are recorded.
- 5.6: MID 0040 is answered by MID 0041 at its header revision (error 97 above
  `max_tool_revision`).
- 5.2.7 / 5.27.1: MID 0008 for MID 0900 is answered by MID 0005 "with the MID subscribed
  for" (`accept_names="subscribed"`, data 0900) or, as some controllers do, naming MID 0008
  (`"subscribing"`); errors 73 (a MID it does not push), 74 (revision), 71, 78, 01. Then
  every tightening with curves pushes one MID 0900 per subscribed trace type; the integrator
  acknowledges each with MID 0005 naming 0900. MID 0009 unsubscribes (72 if not subscribed).
  As 3.9.4 says the generic subscription substitutes MID 0060 and 0070, MID 0008 for MID
  0061 or 0071 subscribes to those too.
- 5.28.1: MID 9999 is mirrored (`mirror_keep_alive`); a link on which nothing is heard for
  `link_timeout_s` (15 s in the specification) is closed.
- 5.2.4: any other MID: MID 0004 error 99; a revision field that is not digits: error 97.

`write_mode` cuts what is written into TCP sends: "whole" (one send a message),
"coalesced" (all a loop turn has to say in one send: the MID 0005 and MID 0076 answering a
MID 0070, a MID 0061 with its MID 0900s), "bytewise" (a byte a send, TCP_NODELAY), or
"random" (cuts at random places, `seed`).
"""

from __future__ import annotations

import time
from dataclasses import replace as replaced
from typing import Any

from tests.support import openprotocol_messages as msg
from tests.support.openprotocol_core import TRACE_MID, ControllerCore, Handler
from tests.support.openprotocol_link import Link, trace_subscription, trace_unsubscription
from tests.support.openprotocol_messages import Alarm, Error
from tests.support.openprotocol_results import (
    TighteningResult,
    last_result,
    last_result_fields,
    old_result,
    old_result_fields,
)
from tests.support.openprotocol_traces import make_curves
from tests.support.openprotocol_wire import Message, frame, hundredths, parameters, whole

#: the largest tightening id (10 digits); the next one is 1
MAX_TIGHTENING_ID = 9_999_999_999


class SpecController(ControllerCore):
    """The controller: a background thread serving 127.0.0.1:`port`. See the module text.

    Settings (keyword arguments of `ControllerCore`): `name`, `accept_names`,
    `max_start_revision` (3), `max_result_revision` (2, MID 0061 and 0065),
    `max_tool_revision` (5), `max_alarm_revision` (2), `max_trace_revision` (1),
    `trace_byte_order` ("big"), `scaling` ("coefficient" = PID 02214, "divisor" = PID 02213),
    `trace_nul_separator` (True), `trace_trailing_nul` (False), `time_unit` ("ms"),
    `alarm_rev2_text` (True), `mirror_keep_alive` (True), `ack_timeout_s` (5), `resends` (3),
    `link_timeout_s` (15), `results_kept` (1000), `write_mode` ("whole"), `seed`,
    `blank_revision_1` (False: revision 1 is written 001, True: three spaces), `identity`.
    """

    # ---- the test's side -------------------------------------------------------------

    def tighten(
        self,
        torque_nm: float = 25.0,
        angle_deg: float = 180.0,
        ok: bool = True,
        pset: int = 1,
        vin: str = "VIN0001",
        batch_size: int = 0,
        batch_counter: int = 0,
        torque_min_nm: float = 20.0,
        torque_max_nm: float = 30.0,
        torque_target_nm: float = 25.0,
        angle_min_deg: float = 90.0,
        angle_max_deg: float = 360.0,
        angle_target_deg: float = 0.0,
        curves: bool = True,
        push: bool = True,
    ) -> int:
        """A tightening: stored (the last `results_kept`), pushed if `push`; its id."""
        now_s = time.time()
        draft = TighteningResult(
            0, torque_nm, angle_deg, ok, pset, vin, batch_size, batch_counter,
            torque_min_nm, torque_max_nm, torque_target_nm,
            angle_min_deg, angle_max_deg, angle_target_deg, now_s, now_s - 3600.0,
        )  # fmt: skip
        last_result(draft, 7, self.identity)  # a value that does not fit raises here
        old_result(draft, 7, self.identity)

        def store() -> int:
            result = replaced(draft, tightening_id=self._next_id)
            # the tightening id is 10 digits: after 9999999999 the counter wraps to 1
            self._next_id = 1 if self._next_id >= MAX_TIGHTENING_ID else self._next_id + 1
            self.results[result.tightening_id] = result
            while len(self.results) > self.results_kept:
                oldest = next(iter(self.results))
                del self.results[oldest]
                self.curves.pop(oldest, None)
            if curves:
                self.curves[result.tightening_id] = make_curves(
                    hundredths(torque_nm) / 100, whole(angle_deg)
                )
            if push and self._link is not None and self._link.started:
                self._push(self._link, result.tightening_id)
            return result.tightening_id

        return self._call(store)

    def restart(self, next_id: int = 1, keep_results: bool = False) -> None:
        """A controller reset: the link is cut, ids start at `next_id`, results go unless kept."""

        def reset() -> None:
            self._end("controller restart")
            self._next_id = next_id
            if not keep_results:
                self.results.clear()
                self.curves.clear()

        self._call(reset)

    def count_from(self, next_id: int) -> None:
        """The next tightening gets `next_id`, the link staying up (e.g. just before a wrap)."""

        def set_counter() -> None:
            self._next_id = next_id

        self._call(set_counter)

    def drop(self) -> None:
        """Cut the TCP link now, without a word."""
        self._call(lambda: self._end("dropped by the test"))

    def raise_alarm(self, code: str, text: str) -> None:
        """An alarm appears: pushed as MID 0071 to an alarm subscriber."""

        def raise_it() -> None:
            self.alarm = Alarm(code, text, time.time())
            revision = self.subscriptions.get(71)
            if self._link is not None and revision is not None:
                data = msg.alarm(self.alarm, revision, rev2_text=self.alarm_rev2_text)
                self._send(self._link, 71, data, revision)

        self._call(raise_it)

    def clear_alarm(self) -> None:
        """The current alarm is acknowledged on the controller: MID 0074 to a subscriber."""

        def clear() -> None:
            if self.alarm is not None and self._link is not None and 71 in self.subscriptions:
                self._send(self._link, 74, msg.alarm_acknowledged(self.alarm))
            self.alarm = None

        self._call(clear)

    def send_raw(self, data: bytes) -> None:
        """Bytes to the connected integrator as they are (hostile tests)."""

        def send() -> None:
            if self._link is not None:
                self._link.outbox.append(data)

        self._call(send)

    def result_wire(
        self,
        tightening_id: int,
        revision: int,
        replace: dict[int, str] | None = None,
        mid: int = 61,
    ) -> bytes:
        """A MID 0061 (or 0065) of a kept result with parameters' value text replaced."""
        result = self.results[tightening_id]
        layout = last_result_fields if mid == 61 else old_result_fields
        fields = [
            (pid, (replace or {}).get(pid, v)) for pid, v in layout(result, revision, self.identity)
        ]
        return frame(mid, parameters(fields), revision, blank_revision_1=self.blank_revision_1)

    def trace_wire(self, tightening_id: int, trace_type: int, **overrides: Any) -> bytes:
        """A MID 0900 of a kept result's curve; `overrides` are `TraceOptions` fields."""
        return self._trace(tightening_id, trace_type, replaced(self.trace_options, **overrides))

    # ---- what the integrator says ----------------------------------------------------

    def _handler_table(self) -> dict[int, Handler]:
        return {
            1: self._on_start,
            3: self._on_stop,
            5: self._on_integrator_accept,
            8: self._on_generic_subscribe,
            9: self._on_generic_unsubscribe,
            40: self._on_tool_data,
            60: self._on_result_subscribe,
            62: self._on_result_ack,
            63: self._on_result_unsubscribe,
            64: self._on_old_result,
            70: self._on_alarm_subscribe,
            72: self._on_ack,
            73: self._on_alarm_unsubscribe,
            75: self._on_ack,
            77: self._on_ack,
            9999: self._on_keep_alive,
        }

    def _on_start(self, link: Link, m: Message) -> None:
        if link.started:
            self._error(link, 1, Error.CLIENT_ALREADY_CONNECTED)
        elif m.revision > self.max_start_revision:
            self._error(link, 1, Error.MID_REVISION_UNSUPPORTED)
        else:
            link.started = True
            self._send(link, 2, msg.start_acknowledge(self.identity, m.revision), m.revision)

    def _on_stop(self, link: Link, m: Message) -> None:
        self.stops += 1
        self._accept_command(link, 3)
        link.ending = "MID 0003 communication stop"

    def _on_keep_alive(self, link: Link, m: Message) -> None:
        if self.mirror_keep_alive:
            link.outbox.append(m.raw + b"\x00")
            self.sent_mids.append(9999)

    def _on_ack(self, link: Link, m: Message) -> None:
        self.acks.append(m.mid)

    def _on_result_subscribe(self, link: Link, m: Message) -> None:
        if 61 in self.subscriptions:
            self._error(link, 60, Error.RESULT_SUBSCRIPTION_EXISTS)
        elif m.revision > self.max_result_revision:
            self._error(link, 60, Error.MID_REVISION_UNSUPPORTED)
        else:
            self.subscriptions[61] = m.revision
            link.result_no_ack = m.no_ack
            self._accept_command(link, 60)

    def _on_result_unsubscribe(self, link: Link, m: Message) -> None:
        if self.subscriptions.pop(61, None) is None:
            self._error(link, 63, Error.RESULT_SUBSCRIPTION_MISSING)
            return
        link.results_due.clear()
        link.in_flight = None
        self._accept_command(link, 63)

    def _on_result_ack(self, link: Link, m: Message) -> None:
        self.acks.append(62)
        self._result_acknowledged(link)

    def _on_integrator_accept(self, link: Link, m: Message) -> None:
        """MID 0005 from the integrator acknowledges a pushed MID 0900 (or a MID 0061)."""
        self.acks.append(5)
        named = m.data[:4]
        if named == b"0900":
            if link.traces_unacknowledged:
                self.trace_acks.append(link.traces_unacknowledged.popleft())
            else:
                self.protocol_errors.append("MID 0005 naming 0900 with no MID 0900 awaited")
        elif named == b"0061":
            self._result_acknowledged(link)

    def _on_old_result(self, link: Link, m: Message) -> None:
        text = m.data[:10]
        if len(text) != 10 or not text.isdigit():
            self._error(link, 64, Error.INVALID_DATA)
            return
        wanted = int(text)
        self.old_result_requests.append((wanted, m.revision))
        if m.revision > self.max_result_revision:
            self._error(link, 64, Error.MID_REVISION_UNSUPPORTED)
            return
        tightening_id = next(reversed(self.results), 0) if wanted == 0 else wanted
        result = self.results.get(tightening_id)
        if result is None:
            self._error(link, 64, Error.TIGHTENING_ID_NOT_FOUND)
            return
        self._send(link, 65, old_result(result, m.revision, self.identity), m.revision)
        self.delivered_ids.append(tightening_id)

    def _on_tool_data(self, link: Link, m: Message) -> None:
        self.tool_data_revisions.append(m.revision)
        if m.revision > self.max_tool_revision:
            self._error(link, 40, Error.MID_REVISION_UNSUPPORTED)
            return
        data = msg.tool_data(self.identity, m.revision, len(self.results))
        self._send(link, 41, data, m.revision)

    def _on_alarm_subscribe(self, link: Link, m: Message) -> None:
        if 71 in self.subscriptions:
            self._error(link, 70, Error.ALARM_SUBSCRIPTION_EXISTS)
        elif m.revision > self.max_alarm_revision:
            self._error(link, 70, Error.MID_REVISION_UNSUPPORTED)
        else:
            self.subscriptions[71] = m.revision
            self._accept_command(link, 70)
            status = msg.alarm_status(self.alarm, m.revision, time.time())
            self._send(link, 76, status, m.revision)

    def _on_alarm_unsubscribe(self, link: Link, m: Message) -> None:
        if self.subscriptions.pop(71, None) is None:
            self._error(link, 73, Error.ALARM_SUBSCRIPTION_MISSING)
        else:
            self._accept_command(link, 73)

    def _generic(self, link: Link, m: Message) -> tuple[int, int, str] | None:
        """MID 0008/0009 data: (MID, revision, extra data), or None once refused."""
        data = m.data.decode("ascii", "replace")
        if len(data) < 9 or not data[:9].isdigit():
            self._error(link, m.mid, Error.INVALID_DATA)
            return None
        return int(data[:4]), max(1, int(data[4:7])), data[9 : 9 + int(data[7:9])]

    def _named(self, m: Message, subscribed_mid: int) -> int:
        return subscribed_mid if self.accept_names == "subscribed" else m.mid

    def _on_generic_subscribe(self, link: Link, m: Message) -> None:
        """MID 0008: MID 0900, or MID 0061 / 0071 in place of MID 0060 / 0070 (3.9.4)."""
        parsed = self._generic(link, m)
        if parsed is None:
            return
        mid, revision, extra = parsed
        named = self._named(m, mid)
        highest = {
            61: self.max_result_revision,
            71: self.max_alarm_revision,
            TRACE_MID: self.max_trace_revision,
        }
        if mid not in highest:
            self._error(link, named, Error.SUBSCRIBED_MID_UNSUPPORTED)
            return
        if revision > highest[mid]:
            self._error(link, named, Error.SUBSCRIBED_MID_REVISION_UNSUPPORTED)
            return
        if mid in self.subscriptions:
            self._error(link, named, Error.SUBSCRIPTION_EXISTS)
            return
        if mid == TRACE_MID:
            types = trace_subscription(extra)
            if isinstance(types, Error):
                self._error(link, named, types)
                return
            link.trace_types = types
        link.result_no_ack = m.no_ack if mid == 61 else link.result_no_ack
        self.subscriptions[mid] = revision
        self._accept_command(link, named)
        if mid == 71:
            self._send(link, 76, msg.alarm_status(self.alarm, revision, time.time()), revision)

    def _on_generic_unsubscribe(self, link: Link, m: Message) -> None:
        """MID 0009: the subscribed MID's subscription ends (for MID 0900, per trace type)."""
        parsed = self._generic(link, m)
        if parsed is None:
            return
        mid, _, extra = parsed
        named = self._named(m, mid)
        if mid not in self.subscriptions:
            self._error(link, named, Error.SUBSCRIPTION_MISSING)
            return
        if mid == TRACE_MID:
            left = trace_unsubscription(extra, link.trace_types)
            if isinstance(left, Error):
                self._error(link, named, left)
                return
            link.trace_types = left
            if left:
                self._accept_command(link, named)
                return
        del self.subscriptions[mid]
        if mid == 61:
            link.results_due.clear()
            link.in_flight = None
        self._accept_command(link, named)
