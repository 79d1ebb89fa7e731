"""What a recording file holds of the stations' spools: said last in each of its chunks, read
back by a recorder that starts after one was killed.

A spooling station numbers what it puts toward the line (:mod:`shared.spool`). The
recorder acknowledges what it saved as filed (``.spool/<station>-<source>.filed.json``,
once a second); what it flushed into a file since is on the disk, not acknowledged:
killed then, it leaves it in its files, and the station sends it again. So each file
of a spooling station says, last in each chunk, which numbers it holds so far: one
:class:`~shared.contract.SpoolFiled` per spool (source and spool id), on a channel of
its own (topic ``boltwatch/<st>/spool/filed``, channel metadata :data:`MARKS_METADATA`
naming the source and the spool). A payload put on that key by anyone else lands on the
key's raw channel, which is never read as marks. A chunk is read whole or not at all
(:mod:`.recording_reader`, :mod:`.recovery`), so marks that can be read name only
messages in the complete chunks before them or in their own: on the disk.
:func:`filed_in` reads the newest marks of each spool of a complete file, through its
index (the last chunk that holds them): a few kilobytes of a file of any size.
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Final

from mcap.exceptions import McapError
from mcap.reader import make_reader

from shared.contract import SeqRange, SpoolFiled, decode
from shared.errors import InputError
from shared.spool import SeqRanges

LOG = logging.getLogger(__name__)

#: the marks' topic below the station (never a channel put on the line)
MARKS_TOPIC: Final = "spool/filed"
#: channel metadata of the marks' channel: what it is, and the spool it speaks of
MARKS_METADATA: Final = "boltwatch.recorder"
MARKS_KIND: Final = "spool_filed"
SOURCE_METADATA: Final = "boltwatch.spool_source"
SPOOL_ID_METADATA: Final = "boltwatch.spool_id"

#: (station, source, spool id)
SpoolKey = tuple[str, str, int]


class FileMarks:
    """The numbers of each spool one file holds, and which spools changed since they were
    last written into it."""

    def __init__(self, station: str) -> None:
        self.station = station
        self._ranges: dict[tuple[str, int], SeqRanges] = {}
        self._changed: set[tuple[str, int]] = set()

    @property
    def changed(self) -> bool:
        return bool(self._changed)

    def add(self, source: str, spool_id: int, seq: int) -> None:
        """Message ``seq`` of that spool is in the file (written, maybe not flushed)."""
        self._ranges.setdefault((source, spool_id), SeqRanges()).add(seq)
        self._changed.add((source, spool_id))

    def take(self, time_ns: int) -> list[SpoolFiled]:
        """The marks of every spool that changed, to be written now (in the chunk being
        ended)."""
        marks = [
            SpoolFiled(
                station=self.station,
                source=source,
                spool_id=spool_id,
                time_ns=time_ns,
                ranges=[SeqRange(first, last) for first, last in self._ranges[(source, spool_id)]],
            )
            for source, spool_id in sorted(self._changed)
        ]
        self._changed.clear()
        return marks


def marks_channel_metadata(source: str, spool_id: int) -> dict[str, str]:
    return {MARKS_METADATA: MARKS_KIND, SOURCE_METADATA: source, SPOOL_ID_METADATA: str(spool_id)}


def filed_in(path: Path) -> dict[SpoolKey, SeqRanges]:
    """The numbers of each spool the complete file ``path`` holds, by its newest marks
    ({} when it has none, or cannot be read: logged; what is not known is sent again by
    the station, and filed again)."""
    try:
        with path.open("rb") as handle:
            reader = make_reader(handle)
            summary = reader.get_summary()
            if summary is None:
                return {}
            channels = {
                channel_id: channel
                for channel_id, channel in summary.channels.items()
                if channel.metadata.get(MARKS_METADATA) == MARKS_KIND
            }
            if not channels:
                return {}
            found: dict[SpoolKey, SeqRanges] = {}
            seen: set[int] = set()
            topics = sorted({channel.topic for channel in channels.values()})
            # newest first (marks are logged at their chunk's end, later each time)
            for _, channel, message in reader.iter_messages(topics=topics, reverse=True):
                if channel.id not in channels or channel.id in seen:
                    continue
                seen.add(channel.id)
                marks = decode(SpoolFiled, message.data)
                found[(marks.station, marks.source, marks.spool_id)] = SeqRanges(
                    (r.first, r.last) for r in marks.ranges
                )
                if seen == set(channels):
                    break
            return found
    except (OSError, McapError, InputError, ValueError) as err:
        LOG.warning("%s: its spool marks cannot be read (%s): what it holds may be filed again",
                    path, err)  # fmt: skip
        return {}
