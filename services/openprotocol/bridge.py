"""The bridge's work: keep a session with the controller, turn what it says into the line's.

One thread (the service's work thread) owns the link: connect, start the
session (:mod:`.controller_session`), subscribe, fill the gap since the last
tightening published, then read what the controller pushes until the link
ends or the service stops; then connect again after a pause that doubles from
``reconnect_min_s`` up to ``reconnect_max_s`` (back to the minimum after a
session that started).

After every (re)connect: 0064 id 0 asks the newest result (0065); every id
after the watermark up to it is fetched (0064 per id, 0065; :mod:`.pending_tightenings`)
and published once, in id order, before newer live ones. Each 0061 is
acknowledged (0062) as soon as it is read, before anything else is done with
it (a controller re-sends an unacknowledged result three times, then drops the
link). A 0061 the codec refuses is acknowledged too, then 0064 id 0 asks the
newest result and the gap up to it is fetched by id: the refused result
comes back as a 0065 even when it was the last one. A controller whose
newest id is below the watermark, or that names itself differently, starts
a new epoch (:mod:`.published_ids`).

Each tightening goes out through the station's queued publisher as a CAN
station's services publish a run (:mod:`.tightening_messages`); the
watermark is written after its last message was put (on the publisher's
thread). Tool data (0041) goes on ``tool_data``, alarms (0071, 0074, 0076) on
``alarms`` (:mod:`.controller_reports`).
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from services.openprotocol.bridge_counts import BridgeCounts
from services.openprotocol.controller_link import ControllerLink, LinkLostError
from services.openprotocol.controller_reports import ControllerReports
from services.openprotocol.controller_session import ControllerSession, RefusedFrame
from services.openprotocol.pending_tightenings import PendingTightenings
from services.openprotocol.published_ids import BridgePosition, read_position, write_position
from services.openprotocol.result_reading import read_curve, read_result
from services.openprotocol.tightening_messages import tightening_messages
from shared.config import AnyStation
from shared.config.openprotocol import OpenProtocolSection
from shared.message_fields import INT64_MAX
from shared.openprotocol.codec import KNOWN_MIDS
from shared.openprotocol.dialect import Dialect
from shared.openprotocol.results import (
    LastTighteningResult,
    OldResultRequest,
    OldTighteningResult,
    ResultAcknowledge,
    ResultSubscribe,
)
from shared.openprotocol.session import CommandAccepted, CommandError
from shared.openprotocol.subscriptions import DataSubscribe, trace_extra_data
from shared.openprotocol.traces import TraceCurve, TraceType
from shared.stopped_run import RunReplay

LOG = logging.getLogger(__name__)

#: how long one read waits before the bridge looks at its timers again (seconds)
POLL_S = 0.05
#: the MID of the answer to 0064
OLD_RESULT = 65
#: 0004 error code: tightening id not found (0064 id 0 on a controller with no result yet)
NOT_FOUND = 15


class OpenProtocolBridge:
    """One station's controller, bridged onto the station's channels."""

    def __init__(
        self,
        station: AnyStation,
        section: OpenProtocolSection,
        publish: Callable[[object], None],
        after_published: Callable[[Callable[[], None]], None],
        replay: RunReplay,
        position_file: Path,
        trace_timeout_s: float,
        counts: BridgeCounts,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        """``after_published(f)``: call ``f`` once what is published so far was put."""
        self._station = station
        self._section = section
        self._publish = publish
        self._after_published = after_published
        self._replay = replay
        self._position_file = position_file
        self._counts = counts
        self._clock = clock
        self._dialect = Dialect(
            header_fill="space" if section.header_fill == "spaces" else "zero",
            trace_byte_order=section.trace_byte_order,
        )
        self.position = read_position(position_file)
        self._pending = PendingTightenings(self.position.watermark, section.traces, trace_timeout_s)
        self._reports = ControllerReports(
            station.station_id, station.config.station.tool_id, section.timezone
        )
        self._session: ControllerSession | None = None
        #: a pushed 0061 was refused: ask the newest result (its id shows the gap)
        self._ask_newest = False

    # -- the link's life -----------------------------------------------------------------

    def work(self, stop: threading.Event) -> None:
        """Connect, serve, reconnect with back-off, until ``stop``."""
        section = self._section
        pause_s = section.reconnect_min_s
        while not stop.is_set():
            try:
                with ControllerLink(
                    section.host,
                    section.port,
                    2.0 * section.keep_alive_s,
                    KNOWN_MIDS,
                ) as link:
                    session = ControllerSession(
                        link, self._counts, section.keep_alive_s, self._dialect, self._pushed
                    )
                    self._session = session
                    self._start(session)
                    pause_s = section.reconnect_min_s
                    self._serve(session, stop)
                    session.stop()
                    return
            except LinkLostError as err:
                if self._counts.connected:  # the session had started (0002)
                    self._counts.link_drops += 1
                    pause_s = section.reconnect_min_s
                self._counts.fault("link", f"link to {self._counts.controller} lost: {err}")
            finally:
                self._session = None
                self._counts.connected = False
                self._counts.result_revision = None
            stop.wait(pause_s)
            pause_s = min(2.0 * pause_s, section.reconnect_max_s)

    def _start(self, session: ControllerSession) -> None:
        session.start()
        self._counts.connects += 1
        self._counts.connected = True
        name = session.controller_name
        if self.position.controller_name and name != self.position.controller_name:
            self._new_epoch(
                f"the controller is now {name!r}, was {self.position.controller_name!r}"
            )
        section = self._section
        revision = session.subscribe(
            lambda rev: ResultSubscribe(revision=rev), 60, section.result_revision
        )
        if revision is None:
            raise LinkLostError("the controller refused the result subscription (MID 0060)")
        self._counts.result_revision = revision
        if section.traces:
            session.subscribe(_trace_subscription, 8, 1)
        self._reports.subscribe(session, self._publish, self._counts)
        self._fill_from_newest(session)
        LOG.info(
            "connected to %s (%s): results at revision %d, traces %s; watermark %d",
            self._counts.controller,
            name or "unnamed",
            revision,
            "on" if section.traces else "off",
            self._pending.watermark,
        )

    def _serve(self, session: ControllerSession, stop: threading.Event) -> None:
        tool_data_asked_s = time.monotonic()
        results_at_ask = self._counts.results
        while not stop.is_set():
            session.poll(POLL_S)
            if self._ask_newest:
                self._ask_newest = False
                self._fill_from_newest(session)
            self._fill(session)
            self._publish_ready()
            # tool data again after each tightening (its counters moved) and every minute:
            # a recorder that was not listening at the connect gets it all the same
            now_s = time.monotonic()
            if self._counts.results != results_at_ask or now_s - tool_data_asked_s >= 60.0:
                self._reports.ask_tool_data(session)
                tool_data_asked_s, results_at_ask = now_s, self._counts.results

    # -- filling the gap -----------------------------------------------------------------

    def _fill_from_newest(self, session: ControllerSession) -> None:
        reply = session.request(
            OldResultRequest(tightening_id=0), {OLD_RESULT}, expected_errors=(NOT_FOUND,)
        )
        if isinstance(reply, CommandError):  # no result yet on the controller
            return
        if isinstance(reply, RefusedFrame):
            return  # counted; the next live result shows the gap
        newest = reply.tightening_id
        if newest < self._pending.watermark:
            self._new_epoch(
                f"its newest tightening id {newest} is below the last published "
                f"{self._pending.watermark}"
            )
        self._take_result(reply, filled=True, repeat_expected=True)
        self._pending.controller_newest(newest)
        self._fill(session)
        self._publish_ready()

    def _fill(self, session: ControllerSession) -> None:
        for tightening_id in self._pending.missing():
            reply = session.request(OldResultRequest(tightening_id=tightening_id), {OLD_RESULT})
            if isinstance(reply, OldTighteningResult) and reply.tightening_id == tightening_id:
                self._take_result(reply, filled=True)
            else:
                why = (
                    f"error {reply.error_code}"
                    if isinstance(reply, CommandError)
                    else "its answer was refused"
                )
                self._counts.fault(
                    "refused value", f"tightening {tightening_id} cannot be fetched ({why})"
                )
                self._pending.give_up(tightening_id)
            self._publish_ready()

    def _new_epoch(self, why: str) -> None:
        name = self._session.controller_name if self._session is not None else ""
        self.position = self.position.new_epoch(name)
        self._pending = PendingTightenings(
            0, self._pending.wait_for_curves, self._pending.trace_timeout_s
        )
        LOG.warning(
            "a new controller epoch (%s): its tightenings get run ids after %d",
            why,
            self.position.run_id_offset,
        )
        self._write_position(self.position)

    # -- what the controller pushes ------------------------------------------------------

    def _pushed(self, message: Any) -> None:
        session = self._session
        if isinstance(message, LastTighteningResult):
            if session is not None:
                session.send(ResultAcknowledge())  # at once: it would be sent again
            self._take_result(message, filled=False)
        elif isinstance(message, RefusedFrame):
            if message.frame.mid == 61 and session is not None:
                session.send(ResultAcknowledge())  # not sent again: fetched by id instead
                self._ask_newest = True  # the newest id shows the gap, the last one too
        elif isinstance(message, TraceCurve):
            if session is not None:
                session.send(CommandAccepted(mid=900))  # the acknowledge of a pushed 0900
            self._take_curve(message)
        elif session is not None:
            self._reports.pushed(message, session, self._publish, self._counts)

    def _take_result(self, message: Any, filled: bool, repeat_expected: bool = False) -> None:
        """``repeat_expected``: the newest result asked after a connect (published already,
        most often): not a repeat of the controller's."""
        figures = read_result(message, self._section.timezone, filled)
        if not self._pending.result(figures, self._clock()):
            if repeat_expected:
                return
            self._counts.repeated_results += 1
            LOG.info(
                "tightening %d again: acknowledged, not published again", figures.tightening_id
            )

    def _take_curve(self, message: TraceCurve) -> None:
        curve = read_curve(message, self._section.timezone)
        if curve is None:
            return  # a trace type the bridge does not use
        if not self._pending.curve(curve, self._clock()):
            self._counts.traces_without_result += 1

    # -- publishing ----------------------------------------------------------------------

    def _publish_ready(self) -> None:
        now = self._clock()
        expired = self._pending.expired_curves(now)
        if expired:
            self._counts.traces_without_result += expired
            self._counts.fault("trace", f"{expired} curve(s) whose result never came: dropped")
        for tightening in self._pending.ready(now):
            result = tightening.result
            run_id = self.position.run_id(result.tightening_id)
            if run_id > INT64_MAX:
                self._counts.refused_values += 1
                self._counts.fault("run id", f"run id {run_id} does not fit 64 bits: not published")
            else:
                self._publish_tightening(tightening, run_id)
            self.position = BridgePosition(
                self._pending.watermark, self.position.run_id_offset, self._controller_name()
            )
            self._write_position(self.position)

    def _publish_tightening(self, tightening: Any, run_id: int) -> None:
        result = tightening.result
        station = self._station
        try:
            program_name = station.config.program(result.program_id).name
        except KeyError:
            program_name = ""
        messages = tightening_messages(
            station.station_id,
            station.config.station.tool_id,
            run_id,
            tightening,
            self._replay,
            program_name,
        )
        for message in messages:
            self._publish(message)
        counts = self._counts
        counts.results += 1
        counts.results_filled += int(result.filled)
        curves = int(tightening.torque is not None) + int(tightening.angle is not None)
        counts.traces += curves
        if self._section.traces and not result.filled and not tightening.complete:
            counts.results_without_traces += 1
            counts.fault(
                "trace", f"tightening {result.tightening_id}: published without its curves"
            )
        counts.last_tightening_id = result.tightening_id

    def _write_position(self, position: BridgePosition) -> None:
        path = self._position_file

        def write() -> None:
            try:
                write_position(path, position)
            except OSError as err:
                self._counts.fault("link", f"{path}: cannot be written: {err.strerror}")

        self._after_published(write)

    def _controller_name(self) -> str:
        return self._session.controller_name if self._session is not None else ""


def _trace_subscription(revision: int) -> DataSubscribe:
    """0008 for 0900: the torque and angle curves of each new result."""
    return DataSubscribe(
        mid=TraceCurve.MID,
        wanted_revision=1,
        extra_data=trace_extra_data([TraceType.TORQUE, TraceType.ANGLE]),
        revision=revision,
    )
