"""The machinery of the test Open Protocol controller: its settings, records, thread and link.

What the controller answers to each MID is in `openprotocol_controller` (with the
specification sections it follows); here are the parts every answer shares: the TCP
server on 127.0.0.1 serving one integrator at a time, the selector loop that reads the
stream, runs the test's commands and checks the timers (acknowledgement of a pushed MID
0061, 4.3.3; link silence, 5.28.1), and the writes, cut as `write_mode` says.
"""

from __future__ import annotations

import random
import selectors
import socket
import threading
import time
import traceback
from collections.abc import Callable
from concurrent.futures import Future
from dataclasses import replace as replaced
from queue import SimpleQueue
from types import TracebackType
from typing import Any, Literal, Self, TypeVar

from tests.support import openprotocol_messages as msg
from tests.support.openprotocol_link import InFlight, Link, WriteMode, writes
from tests.support.openprotocol_messages import Alarm, ControllerIdentity, Error
from tests.support.openprotocol_results import TighteningResult, last_result
from tests.support.openprotocol_traces import ByteOrder, Curves, Scaling, TraceOptions, trace
from tests.support.openprotocol_wire import Message, frame

T = TypeVar("T")
AcceptNames = Literal["subscribed", "subscribing"]
Handler = Callable[[Link, Message], None]
TRACE_MID = 900


class ControllerCore:
    """Settings, records and the serving thread; `SpecController` adds what it answers."""

    def __init__(
        self,
        name: str = "PF6000-EMU",
        *,
        accept_names: AcceptNames = "subscribed",
        max_start_revision: int = 3,
        max_result_revision: int = 2,
        max_tool_revision: int = 5,
        max_alarm_revision: int = 2,
        max_trace_revision: int = 1,
        trace_byte_order: ByteOrder = "big",
        scaling: Scaling = "coefficient",
        trace_nul_separator: bool = True,
        trace_trailing_nul: bool = False,
        time_unit: Literal["ms", "s"] = "ms",
        alarm_rev2_text: bool = True,
        mirror_keep_alive: bool = True,
        ack_timeout_s: float = 5.0,
        resends: int = 3,
        link_timeout_s: float = 15.0,
        results_kept: int = 1000,
        write_mode: WriteMode = "whole",
        seed: int = 0,
        blank_revision_1: bool = False,
        identity: ControllerIdentity | None = None,
    ) -> None:
        self.identity = replaced(identity or ControllerIdentity(), name=name)
        self.accept_names = accept_names
        self.max_start_revision = max_start_revision
        self.max_result_revision = max_result_revision
        self.max_tool_revision = max_tool_revision
        self.max_alarm_revision = max_alarm_revision
        self.max_trace_revision = max_trace_revision
        self.trace_options = TraceOptions(
            byte_order=trace_byte_order,
            scaling=scaling,
            nul_separator=trace_nul_separator,
            trailing_nul=trace_trailing_nul,
            time_unit=time_unit,
            blank_revision_1=blank_revision_1,
        )
        self.alarm_rev2_text = alarm_rev2_text
        self.mirror_keep_alive = mirror_keep_alive
        self.ack_timeout_s = ack_timeout_s
        self.resends = resends
        self.link_timeout_s = link_timeout_s
        self.results_kept = results_kept
        self.write_mode: WriteMode = write_mode
        self.blank_revision_1 = blank_revision_1
        # What happened, for the tests to read (appended by the controller's thread only).
        self.connections = 0
        self.received: list[tuple[int, int]] = []  # (MID, revision) of every message heard
        self.sent_mids: list[int] = []
        self.acks: list[int] = []  # MIDs of the acknowledgements heard (62, 72, 75, 77, 5)
        self.delivered_ids: list[int] = []  # MID 0061 acknowledged or MID 0065 sent (no ack
        # subscription: its MID 0061 are acknowledged by nobody and not counted here)
        self.old_result_requests: list[tuple[int, int]] = []  # (tightening id, revision)
        self.tool_data_revisions: list[int] = []
        self.trace_acks: list[tuple[int, int]] = []  # (tightening id, trace type)
        self.subscriptions: dict[int, int] = {}  # MID pushed (61, 71, 900) -> its revision
        self.stops = 0
        self.errors_sent: list[tuple[int, int]] = []  # (MID named, error code)
        self.protocol_errors: list[str] = []
        self.link_ends: list[str] = []  # why each link ended
        self.faults: list[str] = []  # tracebacks of the controller's own errors
        self.results: dict[int, TighteningResult] = {}
        self.curves: dict[int, Curves] = {}
        self.alarm: Alarm | None = None
        self._next_id = 1
        self._rng = random.Random(seed)
        self._link: Link | None = None
        self._closing = False
        self._commands: SimpleQueue[tuple[Callable[[], Any], Future[Any]]] = SimpleQueue()
        self._changed = threading.Condition()
        self._listener = socket.create_server(("127.0.0.1", 0))
        self._wake_in, self._wake_out = socket.socketpair()
        self._selector = selectors.DefaultSelector()
        self._selector.register(self._listener, selectors.EVENT_READ, "listen")
        self._selector.register(self._wake_in, selectors.EVENT_READ, "wake")
        self._handlers = self._handler_table()
        self._thread = threading.Thread(target=self._run, name="spec-controller", daemon=True)
        self._thread.start()

    @property
    def port(self) -> int:
        return int(self._listener.getsockname()[1])

    @property
    def connected(self) -> bool:
        return self._link is not None

    def wait_for(self, predicate: Callable[[], bool], timeout_s: float = 5.0) -> bool:
        """Whether `predicate` became true within `timeout_s`."""
        with self._changed:
            return self._changed.wait_for(predicate, timeout_s)

    def wait_subscribed(self, timeout_s: float = 5.0, mids: tuple[int, ...] = (61,)) -> bool:
        """Whether the integrator subscribed to every MID of `mids` within `timeout_s`."""
        return self.wait_for(lambda: all(m in self.subscriptions for m in mids), timeout_s)

    def close(self) -> None:
        if not self._closing:
            self._closing = True
            self._wake_out.send(b"!")
            self._thread.join(5.0)
            for sock in (self._listener, self._wake_in, self._wake_out):
                sock.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    def _handler_table(self) -> dict[int, Handler]:
        """Each MID the controller answers, and its handler."""
        raise NotImplementedError

    # ---- the controller's thread -----------------------------------------------------

    def _call(self, command: Callable[[], T]) -> T:
        if self._closing:
            raise RuntimeError("the controller is closed")
        done: Future[T] = Future()
        self._commands.put((command, done))
        self._wake_out.send(b"!")
        return done.result(timeout=10.0)

    def _run(self) -> None:
        while not self._closing:
            try:
                self._turn()
            except Exception:  # a fault of the controller itself: kept for the test to see
                self.faults.append(traceback.format_exc())
                self._end("controller fault")
            with self._changed:
                self._changed.notify_all()
        self._end("controller closed")
        self._selector.close()

    def _turn(self) -> None:
        for key, _ in self._selector.select(self._wait_s()):
            if key.data == "listen":
                self._accept()
            elif key.data == "wake":
                self._wake_in.recv(4096)
                self._run_commands()
            elif self._link is not None:
                self._receive(self._link)
        self._check_timers()
        self._flush()

    def _run_commands(self) -> None:
        while not self._commands.empty():
            command, done = self._commands.get()
            try:
                done.set_result(command())
            except Exception as error:
                done.set_exception(error)

    def _wait_s(self) -> float:
        link, now_s = self._link, time.monotonic()
        if link is None:
            return 0.5
        due = [link.last_heard_s + self.link_timeout_s]
        if link.in_flight is not None:
            due.append(link.in_flight.deadline_s)
        return max(0.0, min(0.5, min(due) - now_s))

    def _accept(self) -> None:
        sock, _ = self._listener.accept()
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        sock.settimeout(5.0)
        self._selector.unregister(self._listener)
        self._selector.register(sock, selectors.EVENT_READ, "link")
        self._link = Link(sock, time.monotonic())
        self.connections += 1

    def _end(self, reason: str) -> None:
        link, self._link = self._link, None
        if link is None:
            return
        self.subscriptions.clear()
        self.link_ends.append(reason)  # before the close, which the integrator sees
        self._selector.unregister(link.sock)
        link.sock.close()
        if not self._closing:
            self._selector.register(self._listener, selectors.EVENT_READ, "listen")

    def _receive(self, link: Link) -> None:
        try:
            data = link.sock.recv(65536)
        except OSError as error:
            self._end(f"receive failed: {error}")
            return
        if not data:
            self._end("closed by the integrator")
            return
        for message in link.reader.feed(data):
            if link.ending is not None:
                break
            self._handle(link, message)
        self.protocol_errors += link.reader.problems[link.problems_seen :]
        link.problems_seen = len(link.reader.problems)
        if link.reader.broken:
            link.ending = "unreadable stream"

    def _handle(self, link: Link, message: Message) -> None:
        link.last_heard_s = time.monotonic()
        self.received.append((message.mid, message.revision))
        if not link.started and message.mid != 1:
            self.protocol_errors.append(f"MID {message.mid:04d} before MID 0001, not answered")
            return
        if message.revision < 0:
            self._error(link, message.mid, Error.MID_REVISION_UNSUPPORTED)
            return
        handler = self._handlers.get(message.mid)
        if handler is None:
            self._error(link, message.mid, Error.UNKNOWN_MID)
        else:
            handler(link, message)

    def _check_timers(self) -> None:
        link, now_s = self._link, time.monotonic()
        if link is None:
            return
        flight = link.in_flight
        if flight is not None and now_s >= flight.deadline_s:
            if flight.sends > self.resends:
                link.ending = f"MID 0061 {flight.tightening_id} unacknowledged after re-sends"
            else:
                flight.sends += 1
                flight.deadline_s = now_s + self.ack_timeout_s
                link.outbox.append(flight.wire)
                self.sent_mids.append(61)
        if now_s - link.last_heard_s >= self.link_timeout_s:
            link.ending = f"nothing heard for {self.link_timeout_s} s"

    def _flush(self) -> None:
        link = self._link
        if link is None:
            return
        chunks, link.outbox = link.outbox, []
        try:
            for piece in writes(chunks, self.write_mode, self._rng):
                link.sock.sendall(piece)
        except OSError as error:
            link.ending = link.ending or f"send failed: {error}"
        if link.ending is not None:
            self._end(link.ending)

    # ---- sending ---------------------------------------------------------------------

    def _send(self, link: Link, mid: int, data: str, revision: int = 1) -> None:
        link.outbox.append(frame(mid, data, revision, blank_revision_1=self.blank_revision_1))
        self.sent_mids.append(mid)

    def _error(self, link: Link, mid: int, error: int) -> None:
        self.errors_sent.append((mid, int(error)))
        self._send(link, 4, msg.command_error(mid, error))

    def _accept_command(self, link: Link, mid: int) -> None:
        self._send(link, 5, msg.command_accepted(mid))

    def _trace(self, tightening_id: int, trace_type: int, options: TraceOptions) -> bytes:
        result, curves = self.results[tightening_id], self.curves[tightening_id]
        values = curves.torque_nm if trace_type == 2 else curves.angle_deg
        context = (result.pset, result.vin, self.identity.tool_serial)
        return trace(tightening_id, result.time_s, trace_type, values, context, options)

    def _push(self, link: Link, tightening_id: int) -> None:
        """A new result: to the result subscriber (queued) and to the trace subscriber."""
        if 61 in self.subscriptions:
            if link.result_no_ack:
                self._send_result(link, tightening_id)
            else:
                link.results_due.append(tightening_id)
                self._push_next_result(link)
        trace_revision = self.subscriptions.get(TRACE_MID)
        if trace_revision is not None and tightening_id in self.curves:
            options = replaced(self.trace_options, revision=trace_revision)
            for trace_type in link.trace_types:
                link.outbox.append(self._trace(tightening_id, trace_type, options))
                link.traces_unacknowledged.append((tightening_id, trace_type))
                self.sent_mids.append(TRACE_MID)

    def _send_result(self, link: Link, tightening_id: int) -> bytes:
        revision = self.subscriptions[61]
        data = last_result(self.results[tightening_id], revision, self.identity)
        self._send(link, 61, data, revision)
        return link.outbox[-1]

    def _push_next_result(self, link: Link) -> None:
        while link.in_flight is None and link.results_due:
            tightening_id = link.results_due.popleft()
            if tightening_id in self.results:
                wire = self._send_result(link, tightening_id)
                deadline_s = time.monotonic() + self.ack_timeout_s
                link.in_flight = InFlight(tightening_id, wire, 1, deadline_s)

    def _result_acknowledged(self, link: Link) -> None:
        if link.in_flight is None:
            self.protocol_errors.append("a MID 0061 acknowledged that was not awaited")
            return
        self.delivered_ids.append(link.in_flight.tightening_id)
        link.in_flight = None
        self._push_next_result(link)
