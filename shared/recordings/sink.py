"""What every writer of a run's recording does: the shape the MCAP and Rerun sinks share.

:class:`~shared.recordings.mcap.mcap_sink.McapSink` (the run's MCAP file, the
record) and :class:`~shared.recordings.rerun.rerun_sink.RerunSink` (its
``.rrd`` beside it, to look at) each take what the recorder received, in
order: one message at a time, or a batch's samples at once; they are flushed
together and closed together. The recorder's run files
(``services/recorder/live/run_files.py``) hand each received message to a
run's sinks through this protocol, whatever they write.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

from shared.recordings.received import Received


class Sink(Protocol):
    """One run's recording being written."""

    def write(self, received: Received) -> None:
        """One received message, in the order received."""

    def write_samples(self, samples: Sequence[Received]) -> None:
        """A batch's samples (decoded, of one station), in order."""

    def flush(self) -> None:
        """What was written reaches the file (and, for the record, the disk)."""

    def close(self) -> None:
        """The recording is finished; safe to call twice."""
