"""The recorder's logic, free of zenoh: received payloads in, MCAP files out.

:class:`Recorder` keeps one :class:`StationFiles` per station seen (the
recorder subscribes to the whole line), counts payloads that do not decode
(logged once per key, still recorded raw) and is driven by a clock tick so
files are flushed even when nothing arrives.
"""

from __future__ import annotations

import logging
from collections import Counter
from pathlib import Path
from typing import TYPE_CHECKING

from services.recorder.file_metadata import FileMetadata
from services.recorder.incoming import Received
from services.recorder.run_files import FileLimits, StationFiles

if TYPE_CHECKING:
    from services.recorder.rerun_sink import RerunOptions

LOG = logging.getLogger(__name__)


class Recorder:
    """File every received payload into its station's run files."""

    def __init__(
        self,
        folder: Path,
        limits: FileLimits,
        metadata: FileMetadata,
        rerun: RerunOptions | None = None,
    ) -> None:
        self._folder = folder
        self._rerun = rerun
        self._limits = limits
        self._metadata = metadata
        self._stations: dict[str, StationFiles] = {}
        self.messages = 0
        self.undecodable: Counter[str] = Counter()
        self.unknown_keys: Counter[str] = Counter()

    def write(self, received: Received) -> None:
        files = self._stations.get(received.station)
        if files is None:
            files = StationFiles(
                received.station, self._folder, self._limits, self._metadata, self._rerun
            )
            self._stations[received.station] = files
        if not received.decodable:
            self._count(self.undecodable, received, "does not decode as %s")
        elif received.schema_name is None:
            self._count(self.unknown_keys, received, "is not a boltwatch message key%s")
        files.write(received)
        self.messages += 1

    def tick(self, now_ns: int) -> None:
        for files in self._stations.values():
            files.tick(now_ns)

    def close(self) -> list[Path]:
        """Finish every open file; the paths of every file closed so far."""
        closed: list[Path] = []
        for files in self._stations.values():
            files.close()
            closed.extend(files.closed_paths)
        if self.undecodable:
            LOG.warning("undecodable payloads, recorded raw: %s", dict(self.undecodable))
        return closed

    def _count(self, counter: Counter[str], received: Received, what: str) -> None:
        if counter[received.key] == 0:
            LOG.warning(
                "payload on %s " + what + "; recording it raw (logged once per key)",
                received.key,
                received.schema_name or "",
            )
        counter[received.key] += 1
