"""The line's recorder filing what stations' spools numbered: live, into holes, or waiting.

Wires the pure :class:`~services.recorder.live.spool_order.SpoolOrder` (through
the :class:`~services.recorder.live.spool_keeper.SpoolKeeper`) to the files of
the :class:`~services.recorder.live.recorder.Recorder`: a hole gets files of
its own (handed the run the live files were recording when it opened, handed
back when it catches up), a live message the hole is not ready for waits in
memory (:mod:`.waiting_live`) and is filed as soon as the hole reaches it
(logged then: what was sent again before it came later than it did, and a
file's log times follow its order), and a hole filled to its end has its
files finished. A station's messages
that carry no number (its spool's own counters) go where its run in progress
is: an open hole's files while there is one. Each numbered message filed is
marked in its file (:meth:`StationFiles.end_message`), for a recorder that
starts after this one is killed. A deferred message's number is
never taken as gone while it waits here (the hole files it); a deferred run
summary goes to the wear ledger at once (``on_deferred``: the ledger counts a
run once, and its row waits in memory while the ledger cannot be written).

A source that starts no runs (a line predictor, :attr:`SpoolOrder.in_order`
False) has no holes: a live message goes where an unnumbered one goes, one
sent again into the file of its run wherever that is open (the live files, a
hole's), else into a file of that run of its own (:meth:`Recorder.files_of_run`).
"""

from __future__ import annotations

from collections.abc import Callable

from services.recorder.live.recorder import Recorder
from services.recorder.live.run_files import StationFiles
from services.recorder.live.spool_keeper import SpoolKeeper
from services.recorder.live.spool_order import Fate, Held, Routing, nothing_held
from services.recorder.live.waiting_live import WaitingLive
from shared.contract import SeqMark, SpoolAck, SpoolStats, channels
from shared.recordings import Received

#: files one received message at a time: (message, filed at, a hole's files or None: live)
FileReceived = Callable[[Received, int, "StationFiles | None"], None]
#: a run's records: kept in memory past the bound of deferred messages
_RECORDS = frozenset(
    channel.schema_name for channel in (channels.RUNS, channels.RESULTS, channels.CONTROLLER)
)


def _no_early(_received: Received) -> None:
    return None


class SpoolFiling:
    """Numbered messages of every spool a recorder hears, into its files."""

    def __init__(
        self,
        keeper: SpoolKeeper,
        recorder: Recorder,
        file: FileReceived,
        on_deferred: Callable[[Received], None] = _no_early,
    ) -> None:
        """``on_deferred``: given each live message deferred (not filed now)."""
        self.keeper = keeper
        self._recorder = recorder
        self._file = file
        self._on_deferred = on_deferred
        self._waiting: dict[tuple[str, str], WaitingLive[tuple[Received, SeqMark]]] = {}
        #: a hole filed something since the last acknowledgement (a station drains its spool)
        self.refiling = False

    def file(self, received: Received, mark: SeqMark, filed_ns: int) -> None:
        """File message ``mark.seq`` where its order says; then what waited for it."""
        self._file_numbered(received, mark, filed_ns)
        waiting = self._waiting.get((received.station, mark.source))
        order = self.keeper.order_of(received.station, mark.source)
        while waiting and order is not None:
            ready = waiting.take(order.next_expected)
            if ready is None:
                return
            kept, kept_mark = ready
            # logged as filed now, after what was sent again before it: a file's log times
            # follow its order (a reader playing it by log time meets its samples in order)
            kept = kept._replace(log_time_ns=max(kept.log_time_ns, filed_ns))
            self._file_numbered(kept, kept_mark, filed_ns)

    def on_stats(self, stats: SpoolStats) -> None:
        """A station's spool counters (what it no longer has is gone, but what waits here)."""
        self.keeper.on_stats(stats, self._held(stats.station, stats.source))

    def _held(self, station: str, source: str) -> Held:
        waiting = self._waiting.get((station, source))
        return nothing_held if waiting is None else waiting.held

    def unnumbered_files(self, station: str) -> StationFiles | None:
        """Where a message of ``station`` without a number goes: the files of a hole holding
        its run in progress; None: the live files."""
        files = self.keeper.open_hole_files(station)
        return files if isinstance(files, StationFiles) else None

    def acknowledge(self, now_ns: int, publish: Callable[[SpoolAck], None]) -> None:
        """Flush the spooling stations' files; acknowledge what they hold."""
        recorder = self._recorder
        self.keeper.acknowledge(now_ns, lambda station: recorder.flush(station, now_ns), publish)
        self.refiling = False
        self._close_holes()

    def waiting_full(self) -> int:
        """Live messages not kept in memory (it was full): the stations send them again."""
        return sum(waiting.full for waiting in self._waiting.values())

    def _file_numbered(self, received: Received, mark: SeqMark, filed_ns: int) -> None:
        station = received.station
        routing = self.keeper.route(
            station, mark, received.run_started, self._held(station, mark.source)
        )
        hole = routing.hole
        if hole is not None and hole.files is None:
            hole.files = self._recorder.hole_files(station, hand_over=routing.opened)
        if routing.fate is Fate.DEFER:
            if not mark.again:
                waiting = self._waiting.setdefault((station, mark.source), WaitingLive())
                record = received.schema_name in _RECORDS
                waiting.keep(mark.seq, (received, mark), len(received.payload), record)
                self._on_deferred(received)
            return
        if routing.fate is Fate.SKIP:
            return
        order = self.keeper.order_of(station, mark.source)
        if order is not None and not order.in_order:
            self._file_of_run(received, mark, filed_ns, routing)
            return
        if routing.caught_up and hole is not None and isinstance(hole.files, StationFiles):
            self._recorder.hand_back(hole.files)
        files = hole.files if routing.fate is Fate.HOLE and hole is not None else None
        self.refiling = self.refiling or files is not None
        self._file_marked(received, mark, filed_ns, files)
        self.keeper.filed_as(station, mark, routing)
        self._close_holes()

    def _file_of_run(
        self, received: Received, mark: SeqMark, filed_ns: int, routing: Routing
    ) -> None:
        """A message of a source that starts no runs: live, where an unnumbered one goes; sent
        again, into a file of its run."""
        station = received.station
        if mark.again:
            files: StationFiles | None = self._recorder.files_of_run(station, received.run_id)
            self.refiling = True
        else:
            files = self.unnumbered_files(station)
        self._file_marked(received, mark, filed_ns, files)
        self.keeper.filed_as(station, mark, routing)

    def _file_marked(
        self, received: Received, mark: SeqMark, filed_ns: int, files: StationFiles | None
    ) -> None:
        """File a numbered message into ``files`` (None: the live files), and say its number
        in the file it went into once it is there."""
        target = files if files is not None else self._recorder.live_files(received.station)
        target.start_message()
        filed = False
        try:
            self._file(received, filed_ns, files)
            filed = True
        finally:  # said in the file it went into
            numbered = (mark.source, mark.spool_id, mark.seq) if filed else None
            self._recorder.end_message(target, numbered, received.log_time_ns)

    def _close_holes(self) -> None:
        for hole in self.keeper.holes_done():
            if isinstance(hole.files, StationFiles):
                self._recorder.close_hole(hole.files)
