"""Store and forward: what a station puts toward the line, kept on its box till the line has it.

- :mod:`.spool_file` (the spool on disk: SQLite, compressed, bounded, durable at each commit)
- :mod:`.station_spool` (what to keep, what the recorder acknowledged, what to send again, at
  what rate; the spool's counters)
- :mod:`.seq_ranges` (sequence numbers as ranges: what a recorder has of a spool)

The station's publisher (:class:`shared.runtime.QueuedPublisher`) keeps every
message here before its put; the line's recorder orders what comes by its
number and acknowledges what it wrote (``services/recorder/live/spool_order.py``).
"""

from shared.spool.seq_ranges import SeqRanges
from shared.spool.spool_file import SpoolDepth, Spooled, SpoolFile
from shared.spool.station_spool import StationSpool, kind_of

__all__ = ["SeqRanges", "SpoolDepth", "SpoolFile", "Spooled", "StationSpool", "kind_of"]
