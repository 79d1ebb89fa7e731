"""From results and curves heard to tightenings published: in order, once, checked, per epoch.

What the bridge takes from its controller (a 0061 pushed, a 0065 fetched, a
0900 curve) comes here, whatever the link; what is ready goes out through the
station's queued publisher as a CAN station's run
(:mod:`.tightening_messages`), and the position (watermark, keys, the curve
reading: :mod:`.published_ids`) is written after its last message was put.

- order and once: :class:`~.pending_tightenings.PendingTightenings`;
- a result whose id was published with another key (or none kept) means the
  controller's ids started again: :meth:`TighteningFlow.new_epoch` publishes
  what is pending of the old epoch, then starts the new one;
- curves are checked against their result (:mod:`.curve_check`); the first
  reading that agrees is kept for the controller (logged, saved); a curve that
  agrees with no reading is refused and counted, its result goes without it;
- each figure is judged against its pset's window: a controller station's
  file's (``[[programs]]`` of that id, where it gives the figure a bound; a CAN
  station's programs are the simulated controller's, whose 0061 says them), else the
  controller's: the result's own limits (0061), or, for a result fetched by id
  (0065 carries none), the limits the controller's last 0061 of that pset
  gave (kept while the bridge runs).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from pathlib import Path

from services.openprotocol.bridge_counts import BridgeCounts
from services.openprotocol.controller_tightening import Curve, ResultFigures, Tightening
from services.openprotocol.curve_check import Reading, check_curves, readings
from services.openprotocol.pending_tightenings import MAX_FILL, PendingTightenings, Take
from services.openprotocol.published_ids import BridgePosition, read_position, write_position
from services.openprotocol.tightening_messages import tightening_messages
from shared.config import (
    AnyStation,
    ControllerProgram,
    ControllerStation,
    OpenProtocolSection,
    Program,
)
from shared.contract import INT64_MAX, TighteningResult
from shared.quality import Window

LOG = logging.getLogger(__name__)


class TighteningFlow:
    """One station's tightenings, from its controller to the line."""

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
        on_result: Callable[[TighteningResult], None] | None = None,
    ) -> None:
        """``after_published(f)``: call ``f`` once what is published so far was put;
        ``on_result``: told each TighteningResult published (a multi-spindle cycle's)."""
        self._on_result = on_result
        self._station = station
        self._section = section
        self._publish = publish
        self._after_published = after_published
        self._position_file = position_file
        self._counts = counts
        self._clock = clock
        self.position = read_position(position_file)
        self._pending = PendingTightenings.resume(
            self.position.watermark,
            self.position.keys,
            section.traces,
            trace_timeout_s,
            self.position.previous_keys,
        )
        self._reading = Reading.parse(self.position.trace_reading)
        counts.trace_reading = None if self._reading is None else str(self._reading)
        #: the controller's name as it said it on the link in use ("" not known)
        self.controller_name = self.position.controller_name
        self._given_up_before = 0  # ids given up in epochs before this one
        #: per pset, the torque and angle windows the controller's last 0061 of it gave
        self._controller_windows: dict[int, dict[str, Window]] = {}
        #: the newest id the controller is known to have on this link (0: none; None: not
        #: known): a live id more than MAX_FILL past it is a jump, not a gap to fetch
        self.session_newest: int | None = None

    @property
    def watermark(self) -> int:
        return self._pending.watermark

    def known_key(self, tightening_id: int) -> str | None:
        """The key of a published id, when it is kept."""
        return self._pending.published_keys.get(tightening_id)

    def last_kept_at_or_below(self, tightening_id: int) -> tuple[int, str] | None:
        """The highest id up to ``tightening_id`` whose key is kept (this epoch's or one
        before), with its key; None: none kept."""
        kept = {**self._pending.previous_keys, **self._pending.published_keys}
        below = [i for i in kept if i <= tightening_id]
        return None if not below else (max(below), kept[max(below)])

    # -- in -----------------------------------------------------------------------------

    def take_result(self, figures: ResultFigures) -> Take:
        """Take a result; a repeat the controller sent is counted (a result fetched by id
        that is here already, or published, is the bridge's own asking, not a repeat); an
        id published with other values starts a new epoch, in which it is taken."""
        if figures.clock_refused:
            self._counts.clock_refused += 1
            self._counts.fault(
                "clock",
                f"tightening {figures.tightening_id}: the controller's time stamp is one no "
                "clock holds: the time it was received is taken",
            )
        tightening_id = figures.tightening_id
        newest = self.session_newest
        if not figures.filled and newest is not None and tightening_id > newest + MAX_FILL:
            self._jump(newest, tightening_id)
        take = self._pending.result(figures, self._clock())
        if take is Take.CONFLICT:
            # live: the controller pushes every result, so its ids went back to this one;
            # fetched (a catch-up): the ids before it may be new too
            self.new_epoch(
                f"tightening {tightening_id} came with other values than the one "
                "published under its id: the controller's ids started again",
                self.controller_name,
                start_after=0 if figures.filled else tightening_id - 1,
            )
            take = self._pending.result(figures, self._clock())
            self.session_newest = tightening_id  # the controller's ids go on from here
        else:
            self.session_newest = max(newest or 0, tightening_id)
        if take is Take.REPEAT and not figures.filled:
            self._counts.repeated_results += 1
            self._counts.note(
                "repeat",
                f"tightening {figures.tightening_id} again: acknowledged, not published again",
            )
        return take

    def take_curve(self, curve: Curve, clock_ok: bool) -> None:
        if not clock_ok:
            self._counts.clock_refused += 1
            self._counts.fault(
                "clock",
                f"curve of tightening {curve.tightening_id}: its time stamp is one no clock "
                "holds: placed at the time it was received",
            )
        if not self._pending.curve(curve, self._clock()):
            self._counts.traces_without_result += 1

    def controller_newest(self, newest: int) -> None:
        self._pending.controller_newest(newest)

    def missing(self) -> list[int]:
        return self._pending.missing()

    def give_up(self, tightening_id: int, why: str) -> None:
        self._counts.fault("refused value", f"tightening {tightening_id} cannot be fetched ({why})")
        self._pending.give_up(tightening_id)

    # -- epochs -------------------------------------------------------------------------

    def _jump(self, newest: int, tightening_id: int) -> None:
        """A live id more than MAX_FILL past the newest the controller had on this link: its
        counter jumped (no controller makes that many while it pushes each). The ids between
        were never made: none is asked for; a new epoch starts just before it."""
        why = f"its tightening id jumped from {newest} to {tightening_id} within a session"
        if self._pending.watermark == 0 and not self._pending.published_keys:
            LOG.warning("%s: %s: the ids before it are not asked for", self._counts.controller, why)
            self._pending = PendingTightenings.resume(
                tightening_id - 1,
                {},
                self._pending.wait_for_curves,
                self._pending.trace_timeout_s,
                self._pending.previous_keys,
                new_epoch=True,
            )
            return
        self.new_epoch(why, self.controller_name, start_after=tightening_id - 1)

    def new_epoch(self, why: str, controller_name: str, start_after: int = 0) -> None:
        """The controller's ids start again after ``start_after``: what is pending of the
        old epoch goes out first; the new epoch's run ids come after every one published."""
        for tightening in self._pending.drain():
            self._publish_one(tightening)
        self._count_given_up()
        self._given_up_before += self._pending.given_up
        self.position = self._current_position().new_epoch(controller_name, start_after)
        self.controller_name = controller_name
        self._pending = PendingTightenings.resume(
            start_after,
            {},
            self._pending.wait_for_curves,
            self._pending.trace_timeout_s,
            previous_keys=self.position.previous_keys,
            new_epoch=True,
        )
        self._reading = None
        self._counts.trace_reading = None
        self._counts.epochs += 1
        self._counts.fault(
            "epoch",
            f"a new controller epoch ({why}): its tightenings get run ids after "
            f"{self.position.run_id_offset}",
        )
        self._write_position()

    # -- out ----------------------------------------------------------------------------

    def publish_ready(self) -> None:
        """Publish every tightening that is ready, in id order."""
        expired = self._pending.expired_curves(self._clock())
        if expired:
            self._counts.traces_without_result += expired
            self._counts.fault("trace", f"{expired} curve(s) whose result never came: dropped")
        published = False
        for tightening in self._pending.ready(self._clock()):
            self._publish_one(tightening)
            published = True
        self._count_given_up()
        if published:
            self._write_position()

    def _publish_one(self, tightening: Tightening) -> None:
        result = tightening.result
        run_id = self.position.run_id(result.tightening_id)
        if run_id > INT64_MAX:
            self._counts.refused_values += 1
            self._counts.fault("run id", f"run id {run_id} does not fit 64 bits: not published")
            return
        tightening = self._checked(tightening)
        station = self._station
        program: Program | ControllerProgram | None
        try:
            program = station.config.program(result.program_id)
        except KeyError:
            program = None
        program_name = f"pset {result.program_id}" if program is None else program.name
        windows = self._windows(result)
        if isinstance(station, ControllerStation) and program is not None:
            for figure in ("torque", "angle"):
                if program.window(figure) != (None, None):
                    windows[figure] = program.window(figure)
        for message in tightening_messages(
            station.station_id,
            station.config.station.tool_of(result.spindle),  # a spindle: its own tool
            run_id,
            tightening,
            program_name,
            windows,
        ):
            self._publish(message)
            if self._on_result is not None and isinstance(message, TighteningResult):
                self._on_result(message)
        counts = self._counts
        counts.results += 1
        counts.results_filled += int(result.filled)
        counts.traces += int(tightening.torque is not None) + int(tightening.angle is not None)
        if self._section.traces and not result.filled and not tightening.complete:
            counts.results_without_traces += 1
            counts.fault(
                "trace", f"tightening {result.tightening_id}: published without its curves"
            )
        counts.last_tightening_id = result.tightening_id

    def _windows(self, result: ResultFigures) -> dict[str, Window]:
        """The controller's windows of ``result``'s pset: a 0061's own are kept for the
        pset; a 0065 (no limits) gets those the pset's last 0061 gave."""
        own = {
            "torque": (result.torque_min_nm, result.torque_max_nm),
            "angle": (result.angle_min_deg, result.angle_max_deg),
        }
        if not result.filled:
            self._controller_windows[result.program_id] = own
            return {}  # the result's own limits: judged as the controller gave them
        return dict(self._controller_windows.get(result.program_id, {}))

    def _checked(self, tightening: Tightening) -> Tightening:
        """The tightening with its curves read the way that agrees with its result."""
        if tightening.torque is None and tightening.angle is None:
            return tightening
        candidates = (
            (self._reading,)
            if self._reading is not None
            else readings(self._section.trace_byte_order)
        )
        checked = check_curves(tightening, candidates)
        for why in checked.refused:
            self._counts.traces_refused += 1
            self._counts.fault("trace", why)
        if checked.reading is not None and self._reading is None:
            self._reading = checked.reading
            self._counts.trace_reading = str(checked.reading)
            LOG.info(
                "the 0900 samples of %s read %s: they agree with its results (kept)",
                self._counts.controller,
                checked.reading,
            )
        return Tightening(tightening.result, checked.torque, checked.angle)

    def _count_given_up(self) -> None:
        self._counts.results_given_up = self._given_up_before + self._pending.given_up

    def _current_position(self) -> BridgePosition:
        return BridgePosition(
            self._pending.watermark,
            self.position.run_id_offset,
            self.controller_name,
            dict(self._pending.published_keys),
            "" if self._reading is None else self._reading.text,
            self.position.previous_keys,
        )

    def _write_position(self) -> None:
        self.position = position = self._current_position()
        path = self._position_file

        def write() -> None:
            try:
                write_position(path, position)
            except OSError as err:
                self._counts.fault("link", f"{path}: cannot be written: {err.strerror}")

        self._after_published(write)
