"""The bridge's work: keep a session with the controller, turn what it says into the line's.

One thread (the service's work thread) owns the link: connect, start the
session (:mod:`.controller_session`), subscribe, catch up with what the
controller made since the last tightening published, then read what it
pushes until the link ends or the service stops; then connect again after a
pause that doubles from ``reconnect_min_s`` up to ``reconnect_max_s`` (back
to the minimum after a session that started).

Catching up, after every (re)connect: 0064 id 0 asks the newest result
(0065); every id after the watermark up to it is fetched (0064 per id) and
published once, in id order, before newer live ones. 0064 is asked at the
highest revision both sides know (one lower on error 97). Before that, the
controller is checked for a new **epoch** (its ids started again: reset,
replaced): it has no result though some were published (0004 error 15 for id
0), its newest id is below the watermark, or its result at the watermark is
not the one published (:attr:`ResultFigures.key`); so is a controller that
names itself differently in 0002, and a live 0061 whose id was published
with another key (ids that wrapped after 9999999999).

Each 0061 is acknowledged (0062) as soon as it is read, before anything else
is done with it (a controller re-sends an unacknowledged result, then drops
the link). A 0061 the codec refuses is acknowledged too, then the catch-up
runs again: the refused result comes back as a 0065 by id. One message that
cannot be used (refused by the codec, a curve with no time step, a value no
clock or float holds) costs that message, counted and logged once per kind,
never the bridge.

Tightenings go out through :mod:`.tightening_flow`; tool data (0041) on
``tool_data``, alarms (0071, 0074, 0076) on ``alarms`` (:mod:`.controller_reports`).
A multi-spindle system (``[openprotocol] multi_spindle``, or a CAN station file of
several spindles) is subscribed to its multi-spindle result (0100, at the highest
revision it takes, one lower on error 97) and status (0090); each 0101 and 0091
is acknowledged at once (0102, 0092) and makes the cycle's common result on
``cycles`` (:mod:`.controller_cycles`).
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from services.openprotocol.bridge_counts import BridgeCounts
from services.openprotocol.controller_cycles import ControllerCycles
from services.openprotocol.controller_link import ControllerLink, LinkLostError
from services.openprotocol.controller_reports import ControllerReports
from services.openprotocol.controller_session import (
    ControllerSession,
    RefusedFrame,
    SessionStoppedError,
)
from services.openprotocol.published_ids import BridgePosition
from services.openprotocol.result_reading import (
    CurveRefusedError,
    controller_time_ns,
    read_curve,
    read_result,
)
from services.openprotocol.tightening_flow import TighteningFlow
from shared.config import AnyStation, OpenProtocolSection
from shared.openprotocol import (
    KNOWN_MIDS,
    SUPPORTED_REVISIONS,
    CommandAccepted,
    CommandError,
    DataSubscribe,
    Dialect,
    LastTighteningResult,
    MultiSpindleResult,
    MultiSpindleResultAcknowledge,
    MultiSpindleResultSubscribe,
    MultiSpindleStatus,
    MultiSpindleStatusAcknowledge,
    MultiSpindleStatusSubscribe,
    OldResultRequest,
    OldTighteningResult,
    OpenProtocolError,
    ResultAcknowledge,
    ResultSubscribe,
    TraceCurve,
    TraceType,
    trace_extra_data,
)

LOG = logging.getLogger(__name__)

#: how long one read waits before the bridge looks at its timers again (seconds)
POLL_S = 0.05
#: the MID of the answer to 0064
OLD_RESULT = 65
#: 0004 error code: tightening id not found (0064 id 0 on a controller with no result yet)
NOT_FOUND = 15
#: the MID of the multi-spindle result, whose revision its subscription (0100) asks
CYCLE_RESULT = 101
#: how much longer than a tightening's curves a cycle waits for its spindles' tightenings
CYCLE_MARGIN_S = 2.0
#: what one message that cannot be used raises (beyond the codec's own refusal)
UNUSABLE = (OpenProtocolError, CurveRefusedError, ValueError, OverflowError, ArithmeticError)


class OpenProtocolBridge:
    """One station's controller, bridged onto the station's channels."""

    def __init__(
        self,
        station: AnyStation,
        section: OpenProtocolSection,
        publish: Callable[[object], None],
        after_published: Callable[[Callable[[], None]], None],
        position_file: Path,
        trace_timeout_s: float,
        counts: BridgeCounts,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        """``after_published(f)``: call ``f`` once what is published so far was put."""
        self._section = section
        self._publish = publish
        self._counts = counts
        spindles = getattr(station.config.station, "spindles", 1)
        #: a multi-spindle system's cycles (None: a controller of one spindle)
        self._cycles = (
            ControllerCycles(station.station_id, publish, trace_timeout_s + CYCLE_MARGIN_S, clock)
            if section.multi_spindle or spindles > 1
            else None
        )
        self._dialect = Dialect(
            header_fill="space" if section.header_fill == "spaces" else "zero",
            trace_byte_order="little" if section.trace_byte_order == "little" else "big",
        )
        self._flow = TighteningFlow(
            station,
            section,
            publish,
            after_published,
            position_file,
            trace_timeout_s,
            counts,
            clock,
            on_result=None if self._cycles is None else self._cycles.on_tightening,
        )
        self._reports = ControllerReports(
            station.station_id, station.config.station.tool_id, section.timezone
        )
        self._session: ControllerSession | None = None
        #: a pushed 0061 was refused: catch up again (its id comes back by 0064)
        self._ask_newest = False
        #: the 0065 revision the controller answers on this link (asked from the highest)
        self._old_result_revision = max(SUPPORTED_REVISIONS[OLD_RESULT])

    @property
    def position(self) -> BridgePosition:
        return self._flow.position

    # -- the link's life -----------------------------------------------------------------

    def work(self, stop: threading.Event) -> None:
        """Connect, serve, reconnect with back-off, until ``stop``."""
        section = self._section
        pause_s = section.reconnect_min_s
        while not stop.is_set():
            try:
                with ControllerLink(
                    section.host, section.port, 2.0 * section.keep_alive_s, KNOWN_MIDS
                ) as link:
                    session = ControllerSession(
                        link,
                        self._counts,
                        section.keep_alive_s,
                        self._dialect,
                        self._pushed,
                        stop,
                    )
                    self._session = session
                    try:
                        self._start(session)
                        pause_s = section.reconnect_min_s
                        self._serve(session, stop)
                    except SessionStoppedError:
                        pass
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
        flow = self._flow
        name = session.controller_name
        if flow.controller_name and name != flow.controller_name:
            flow.new_epoch(f"the controller is now {name!r}, was {flow.controller_name!r}", name)
        flow.controller_name = name
        self._old_result_revision = max(SUPPORTED_REVISIONS[OLD_RESULT])
        newest = self._newest_of_this_epoch(session)  # before any subscription: nothing live
        section = self._section
        revision = session.subscribe(
            lambda rev: ResultSubscribe(revision=rev), section.result_revision, required=True
        )
        if revision is None:
            raise LinkLostError("the controller refused the result subscription (MID 0060)")
        self._counts.result_revision = revision
        if section.traces:
            session.subscribe(_trace_subscription, 1)
        if self._cycles is not None:
            highest = max(SUPPORTED_REVISIONS[CYCLE_RESULT])
            session.subscribe(_cycle_subscription, highest)
            session.subscribe(lambda rev: MultiSpindleStatusSubscribe(revision=rev), 1)
        self._reports.subscribe(session, self._publish, self._counts)
        if newest is not None:
            self._take_newest(newest)
        self._fill(session)
        flow.publish_ready()
        LOG.info(
            "connected to %s (%s): results at revision %d, traces %s; watermark %d",
            self._counts.controller,
            name or "unnamed",
            revision,
            "on" if section.traces else "off",
            flow.watermark,
        )

    def _serve(self, session: ControllerSession, stop: threading.Event) -> None:
        tool_data_asked_s = time.monotonic()
        results_at_ask = self._counts.results
        while not stop.is_set():
            session.poll(POLL_S)
            if self._ask_newest:
                self._ask_newest = False
                self._catch_up(session)
            self._fill(session)
            self._flow.publish_ready()
            if self._cycles is not None:
                self._cycles.publish_ready()
            # tool data again after each tightening (its counters moved) and every minute:
            # a recorder that was not listening at the connect gets it all the same
            now_s = time.monotonic()
            if self._counts.results != results_at_ask or now_s - tool_data_asked_s >= 60.0:
                self._reports.ask_tool_data(session)
                tool_data_asked_s, results_at_ask = now_s, self._counts.results

    # -- catching up ---------------------------------------------------------------------

    def _newest_of_this_epoch(self, session: ControllerSession) -> Any:
        """The controller's newest result (0064 id 0), after a new epoch is started if its
        ids started again since the watermark; None: it has none, or it was not given."""
        flow = self._flow
        flow.session_newest = None
        reply = self._old_result(session, 0)
        if isinstance(reply, CommandError):
            if reply.error_code == NOT_FOUND:
                flow.session_newest = 0
            if reply.error_code == NOT_FOUND and flow.watermark > 0:
                # no newest result: reset, unless it gives the published one (a controller
                # that does not take id 0 for its newest)
                known = flow.known_key(flow.watermark)
                at_watermark = self._figures(self._old_result(session, flow.watermark))
                if at_watermark is None or (known is not None and at_watermark.key != known):
                    flow.new_epoch(
                        f"it has no result, though tightening {flow.watermark} was published",
                        flow.controller_name,
                    )
            return None
        newest = self._figures(reply)
        if newest is not None:
            why = self._epoch_ended(session, newest)
            if why is not None:
                flow.new_epoch(why, flow.controller_name, self._epoch_start(session, newest))
            flow.session_newest = newest.tightening_id
        return newest

    def _epoch_start(self, session: ControllerSession, newest: Any) -> int:
        """After which id a new epoch starts: where the controller's ids went back below
        the watermark to ones it still keeps (the last id up to its newest whose key is
        kept, and its result there is that one), after that one; else after 0 (reset)."""
        if newest.tightening_id >= self._flow.watermark:
            return 0  # its result at the watermark is another one: its ids started again
        kept = self._flow.last_kept_at_or_below(newest.tightening_id)
        if kept is None:
            return 0
        tightening_id, key = kept
        there = newest
        if tightening_id != newest.tightening_id:
            there = self._figures(self._old_result(session, tightening_id))
        if there is None or there.key != key:
            return 0
        LOG.info(
            "%s keeps tightening %d as published: the new epoch starts after it",
            self._counts.controller,
            tightening_id,
        )
        return int(tightening_id)

    def _catch_up(self, session: ControllerSession) -> None:
        """The newest result and the gap up to it (a pushed 0061 was refused)."""
        newest = self._figures(self._old_result(session, 0))
        if newest is None:
            return  # not answered, refused or none (counted): the next live result shows it
        self._take_newest(newest)
        self._fill(session)
        self._flow.publish_ready()

    def _take_newest(self, newest: Any) -> None:
        self._flow.take_result(newest)
        self._flow.controller_newest(newest.tightening_id)

    def _epoch_ended(self, session: ControllerSession, newest: Any) -> str | None:
        """Why the controller's ids started again since the watermark, or None."""
        watermark = self._flow.watermark
        if newest.tightening_id < watermark:
            return (
                f"its newest tightening id {newest.tightening_id} is below the last "
                f"published {watermark}"
            )
        known = self._flow.known_key(watermark)
        if watermark == 0 or known is None:
            return None
        at_watermark = newest
        if newest.tightening_id > watermark:
            at_watermark = self._figures(self._old_result(session, watermark))
        if at_watermark is None:
            LOG.info(
                "%s no longer gives tightening %d: its ids are taken to go on",
                self._counts.controller,
                watermark,
            )
            return None
        if at_watermark.key != known:
            return (
                f"its tightening {watermark} is not the one published "
                f"({at_watermark.key} where {known} was)"
            )
        return None

    def _fill(self, session: ControllerSession) -> None:
        for tightening_id in self._flow.missing():
            reply = self._old_result(session, tightening_id)
            figures = self._figures(reply)
            if figures is not None and figures.tightening_id == tightening_id:
                self._flow.take_result(figures)
            else:
                why = (
                    f"error {reply.error_code}"
                    if isinstance(reply, CommandError)
                    else "its answer was refused or did not come"
                )
                self._flow.give_up(tightening_id, why)
            self._flow.publish_ready()

    def _old_result(self, session: ControllerSession, tightening_id: int) -> Any:
        """0064 for ``tightening_id`` (0: the newest) at the highest revision the controller
        answers: its 0065, a 0004, or None (no answer, or a refused one)."""
        revision, reply = session.request_highest(
            lambda rev: OldResultRequest(tightening_id=tightening_id, revision=rev),
            {OLD_RESULT},
            self._old_result_revision,
            expected_errors=(NOT_FOUND,),
        )
        self._old_result_revision = revision
        return None if isinstance(reply, RefusedFrame) else reply

    def _figures(self, reply: Any) -> Any:
        """A 0065's figures (filled); None for anything else or a value that cannot be used."""
        if not isinstance(reply, OldTighteningResult):
            return None
        try:
            return read_result(reply, self._section.timezone, True, time.time_ns())
        except UNUSABLE as err:
            self._unusable(reply, err)
            return None

    # -- what the controller pushes ------------------------------------------------------

    def _pushed(self, message: Any) -> None:
        try:
            self._take_pushed(message)
        except UNUSABLE as err:
            self._unusable(message, err)

    def _take_pushed(self, message: Any) -> None:
        session = self._session
        if isinstance(message, LastTighteningResult):
            if session is not None:
                session.send(ResultAcknowledge())  # at once: it would be sent again
            self._live_result(message)
        elif isinstance(message, RefusedFrame):
            if session is not None and message.frame.mid == LastTighteningResult.MID:
                session.send(ResultAcknowledge())  # not sent again: fetched by id instead
                self._ask_newest = True  # the newest id shows the gap, the last one too
            elif session is not None and message.frame.mid == TraceCurve.MID:
                session.send(CommandAccepted(mid=TraceCurve.MID))
        elif isinstance(message, MultiSpindleResult | MultiSpindleStatus):
            self._cycle(message)
        elif isinstance(message, TraceCurve):
            if session is not None:
                session.send(CommandAccepted(mid=TraceCurve.MID))  # a pushed 0900's receipt
            try:
                curve, clock_ok = read_curve(message, self._section.timezone, time.time_ns())
            except (CurveRefusedError, OpenProtocolError) as err:
                self._counts.traces_refused += 1
                self._counts.fault("trace", f"curve refused: {err}")
                return
            if curve is not None:
                self._flow.take_curve(curve, clock_ok)
        elif session is not None:
            self._reports.pushed(message, session, self._publish, self._counts)

    def _cycle(self, message: MultiSpindleResult | MultiSpindleStatus) -> None:
        """A multi-spindle system's cycle: acknowledged at once, then made a cycle."""
        session, cycles = self._session, self._cycles
        result = isinstance(message, MultiSpindleResult)
        if session is not None:
            ack = MultiSpindleResultAcknowledge() if result else MultiSpindleStatusAcknowledge()
            session.send(ack)
        if cycles is None:
            return  # not asked for: acknowledged, nothing made of it
        text = message.timestamp if isinstance(message, MultiSpindleResult) else message.time
        time_ns, _ = controller_time_ns(text, self._section.timezone, time.time_ns())
        if isinstance(message, MultiSpindleResult):
            cycles.on_result(message, time_ns)
        else:
            cycles.on_status(message, time_ns)

    def _live_result(self, message: LastTighteningResult) -> None:
        self._flow.take_result(read_result(message, self._section.timezone, False, time.time_ns()))

    def _unusable(self, message: Any, err: Exception) -> None:
        mid = getattr(message, "MID", 0)
        self._counts.refused_values += 1
        self._counts.fault("refused value", f"MID {mid:04d} cannot be used: {err}: ignored")


def _cycle_subscription(revision: int) -> MultiSpindleResultSubscribe:
    """0100 at ``revision`` (the 0101 revision asked): from revision 2 on, no rewind (0) and,
    from 3 on, only the cycles made from now (the bridge takes what it hears live)."""
    return MultiSpindleResultSubscribe(
        data_no_system=0 if revision >= 2 else None,
        send_only_new=True if revision >= 3 else None,
        revision=revision,
    )


def _trace_subscription(revision: int) -> DataSubscribe:
    """0008 for 0900: the torque and angle curves of each new result."""
    return DataSubscribe(
        mid=TraceCurve.MID,
        wanted_revision=1,
        extra_data=trace_extra_data([TraceType.TORQUE, TraceType.ANGLE]),
        revision=revision,
    )
