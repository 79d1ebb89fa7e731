"""The recorder's side of store and forward: what it filed of each station's spool, kept and
acknowledged.

One :class:`~services.recorder.live.spool_order.SpoolOrder` per (station,
source) says where each numbered message goes (:meth:`SpoolKeeper.route`).
Once a second (:meth:`SpoolKeeper.acknowledge`) the recorder flushes the
station's files; what they hold is then saved
(``<recordings>/.spool/<station>-<source>.filed.json``, replaced atomically)
and acknowledged to the station (:class:`~shared.contract.SpoolAck`), which
deletes it from its spool. So a station deletes only what is on the
recorder's disk, and a recorder that restarts knows what it has: the numbers
missing below the highest it saved are holes to fill again.

What the recorder flushed since its last save is on its disk, not in the
saved state: a recorder killed then would file it a second time when the
station sends it again. So each file says which numbers it holds
(:mod:`shared.recordings.mcap.spool_marks`), and a recorder, when it first
hears of a spool, reads that of the station's files written since its state
was saved (their modification time, less :data:`MARKS_MARGIN_S`: the files
the killed recorder had open, finished by :func:`~shared.recordings.mcap.finish_unfinished`
before, and those it finished after its last save): those numbers are filed
already, and acknowledged at once. A state file is saved as soon as a spool
is first heard of, before anything of it is filed, so its time always comes
before what it does not hold.

A flush that fails (a full disk) acknowledges nothing: the order goes back to
what was saved, and the station sends the rest again once the disk takes it
(at least once: what the failed files held may come twice, never not at
all). A message from a spool of another id (the station's spool was made
again: its numbers start from 1 again) starts that source afresh.

A source that may start a run (it puts ``tool``: the station's acquisition, a
controller bridge) is filed in order; any other (a line predictor) as its
messages first come (:attr:`SpoolOrder.in_order`).
"""

from __future__ import annotations

import json
import logging
from collections.abc import Callable
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Final

from services.recorder.live.spool_order import Held, Hole, Routing, SpoolOrder, nothing_held
from shared.contract import SeqMark, SeqRange, SpoolAck, SpoolStats, channels
from shared.files import describe_os_error, write_json_atomically
from shared.recordings import recording_files, station_days
from shared.recordings.mcap import SpoolKey, filed_in
from shared.spool import SeqRanges

LOG = logging.getLogger(__name__)

#: the recorder's state, in its recordings folder
STATE_FOLDER: Final = ".spool"
#: at most this many ranges above ``through`` in one acknowledgement (the station sends the
#: rest again, and they are skipped)
MAX_ACK_RANGES: Final = 256
#: the sources whose messages may start a run (they put tool states): filed in order
RUN_STARTING_SOURCES: Final = frozenset(channels.TOOL.publishers)


def in_order(source: str) -> bool:
    """Whether ``source``'s messages are filed in order (it starts the runs they belong to)."""
    return source in RUN_STARTING_SOURCES


#: the files whose spool marks are read at a spool's first message: modified since the
#: station's state was saved, less this (the clock's steps, a file system's coarse times)
MARKS_MARGIN_S: Final = 60.0


@dataclass
class SpoolSource:
    """What the recorder has of one spool (one source of one station)."""

    station: str
    source: str
    spool_id: int
    order: SpoolOrder
    path: Path
    saved: SeqRanges  # on the recorder's disk, as far as it knows: what it acknowledges
    saved_gone: int = 0

    def ack(self, now_ns: int) -> SpoolAck:
        through = self.saved.through
        ranges = [SeqRange(first, last) for first, last in self.saved.above(through)]
        return SpoolAck(
            station=self.station,
            source=self.source,
            spool_id=self.spool_id,
            time_ns=now_ns,
            through=through,
            ranges=ranges[:MAX_ACK_RANGES],
        )


class SpoolKeeper:
    """Every spool the recorder hears of, by (station, source)."""

    def __init__(self, recordings_folder: Path) -> None:
        self._recordings = recordings_folder
        self._folder = recordings_folder / STATE_FOLDER
        self._sources: dict[tuple[str, str], SpoolSource] = {}
        self._closing: list[Hole] = []  # holes let go of: their files to close
        #: per station: the numbers its files hold, by spool (read once, at its first spool)
        self._on_disk: dict[str, dict[SpoolKey, SeqRanges]] = {}
        self.save_errors = 0
        self.last_error: str | None = None

    def route(
        self, station: str, mark: SeqMark, run_started: bool, held: Held = nothing_held
    ) -> Routing:
        """Where message ``mark.seq`` goes (:meth:`SpoolOrder.route`; ``held``: the numbers
        of its source kept in memory)."""
        order = self._source(station, mark.source, mark.spool_id).order
        return order.route(mark.seq, run_started, mark.kept_before, held)

    def filed_as(self, station: str, mark: SeqMark, routing: Routing) -> None:
        self._source(station, mark.source, mark.spool_id).order.filed_as(mark.seq, routing)

    def on_stats(self, stats: SpoolStats, held: Held = nothing_held) -> None:
        """A station's spool counters: what it no longer has (nor is ``held``) is gone."""
        source = self._source(stats.station, stats.source, stats.spool_id)
        oldest = stats.oldest_seq if stats.messages else stats.head_seq + 1
        gone = source.order.station_has_from(oldest, held)
        if gone:
            LOG.error(
                "%s: %d messages of its %s spool are gone (dropped to keep its bound) "
                "before the recorder had them",
                stats.station,
                gone,
                stats.source,
            )

    def holes_done(self) -> list[Hole]:
        """Holes filled to their end, or let go of: their files are to be closed."""
        done, self._closing = self._closing, []
        for source in self._sources.values():
            done.extend(source.order.completed())
        return done

    def order_of(self, station: str, source: str) -> SpoolOrder | None:
        known = self._sources.get((station, source))
        return None if known is None else known.order

    def open_hole_files(self, station: str) -> object | None:
        """The files of a hole of ``station`` that holds its run in progress (None: none)."""
        for source in self.sources(station):
            opened = source.order.open_hole
            if opened is not None and opened.files is not None:
                return opened.files
        return None

    def sources(self, station: str) -> list[SpoolSource]:
        return [source for source in self._sources.values() if source.station == station]

    def acknowledge(
        self, now_ns: int, flush: Callable[[str], bool], publish: Callable[[SpoolAck], None]
    ) -> None:
        """Flush each spooling station's files; save and acknowledge what they hold (or, when
        the flush failed, go back to what was saved)."""
        for station in sorted({source.station for source in self._sources.values()}):
            flushed = flush(station)
            for source in self.sources(station):
                if flushed:
                    self._save(source)
                else:
                    self._closing.extend(source.order.holes)
                    source.order = SpoolOrder.resumed(
                        SeqRanges(source.saved), source.saved_gone, in_order(source.source)
                    )
                publish(source.ack(now_ns))

    def _source(self, station: str, name: str, spool_id: int) -> SpoolSource:
        source = self._sources.get((station, name))
        if source is not None and source.spool_id == spool_id:
            return source
        if source is not None:
            LOG.warning(
                "%s: its %s spool is a new one (id %d, was %d): its numbers start again",
                station,
                name,
                spool_id,
                source.spool_id,
            )
            self._closing.extend(source.order.holes)
        source = self._load(station, name, spool_id)
        self._sources[(station, name)] = source
        return source

    def _load(self, station: str, name: str, spool_id: int) -> SpoolSource:
        path = self._folder / f"{station}-{name}.filed.json"
        filed, gone, known = SeqRanges(), 0, False
        try:
            document = json.loads(path.read_text(encoding="utf-8"))
            if document.get("spool_id") == spool_id:
                filed = SeqRanges(tuple(pair) for pair in document["filed"])
                gone = int(document.get("gone", 0))
                known = True
        except FileNotFoundError:
            pass
        except (OSError, ValueError, KeyError, TypeError) as err:
            LOG.error("%s: unreadable, the spool of %s starts afresh: %s", path, station, err)
        saved = SeqRanges(filed)
        on_disk = self._filed_on_disk(station).get((station, name, spool_id))
        if on_disk is not None:
            new = [pair for first, last in on_disk for pair in _not_in(first, last, filed)]
            if new:
                LOG.info(
                    "%s: %d messages of its %s spool are in its files already (filed by a "
                    "recorder that stopped before it acknowledged them): not filed again",
                    station,
                    sum(last - first + 1 for first, last in new),
                    name,
                )
            for first, last in new:
                filed.add_range(first, last)
        source = SpoolSource(
            station,
            name,
            spool_id,
            SpoolOrder.resumed(filed, gone, in_order(name)),
            path,
            saved,
            gone,
        )
        if not known:  # saved before anything of it is filed: what is not in it is newer
            self._save(source, always=True)
        return source

    def _filed_on_disk(self, station: str) -> dict[SpoolKey, SeqRanges]:
        """What the station's files written since its state was saved say they hold."""
        found = self._on_disk.get(station)
        if found is not None:
            return found
        found = {}
        states = self._folder.glob(f"{_glob_safe(station)}-*.filed.json")
        saved_s = [modified for path in states if (modified := _modified_s(path)) >= 0]
        if saved_s:
            since_s = min(saved_s) - MARKS_MARGIN_S
            first_day = datetime.fromtimestamp(since_s, UTC).date()
            for day, folder in station_days(self._recordings, station):
                if day < first_day:
                    continue
                for path in recording_files(folder):
                    if _modified_s(path) >= since_s:
                        for key, numbers in filed_in(path).items():
                            known = found.setdefault(key, SeqRanges())
                            for first, last in numbers:
                                known.add_range(first, last)
        self._on_disk[station] = found
        return found

    def _save(self, source: SpoolSource, always: bool = False) -> None:
        order = source.order
        if order.filed == source.saved and order.gone == source.saved_gone and not always:
            return
        document = {
            "station": source.station,
            "source": source.source,
            "spool_id": source.spool_id,
            "filed": order.filed.as_list(),
            "gone": order.gone,
        }
        try:
            write_json_atomically(source.path, document)
        except OSError as err:
            self.save_errors += 1
            self.last_error = describe_os_error(err, source.path)
            LOG.error("spool state not saved (nothing acknowledged): %s", self.last_error)
            return
        source.saved = SeqRanges(order.filed)
        source.saved_gone = order.gone


def _not_in(first: int, last: int, filed: SeqRanges) -> list[tuple[int, int]]:
    """The parts of ``first``..``last`` not in ``filed``."""
    parts = []
    start = first
    for filed_first, filed_last in filed:
        if filed_last < start or filed_first > last:
            continue
        if filed_first > start:
            parts.append((start, filed_first - 1))
        start = max(start, filed_last + 1)
    if start <= last:
        parts.append((start, last))
    return parts


def _glob_safe(name: str) -> str:
    """A station id as a literal part of a glob pattern (ids hold no glob characters; a
    name that does matches nothing)."""
    return "".join(f"[{c}]" if c in "*?[" else c for c in name)


def _modified_s(path: Path) -> float:
    try:
        return path.stat().st_mtime
    except FileNotFoundError:
        return -1.0
