"""The runs the page has read, kept for the next browser that asks: bounded, thread-safe.

A run read from its recording is kept as what the page sends and overlays: its view
(gzipped JSON, :func:`~shared.offline.post_mortem.run_document`) and its curves as
arrays (:class:`~shared.offline.overlay.OverlayRun`, for a part's overlay and a
program's band). An entry stands for its files as they were read (path, size,
modification time of each: :meth:`~.run_locator.LocatedRun.signature`): a run whose
file changed since (still being written, finished under its name, recovered, deleted)
is read again. At most :data:`CACHE_RUNS` runs and :data:`CACHE_BYTES` bytes are kept,
the least recently asked for going first: some 60 MB at most, a run of 3000 samples
about 150 kB.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from dataclasses import dataclass

from shared.offline.overlay import OverlayRun
from shared.results import StoredResult

#: runs kept at most, and their bytes (views and curves) at most
CACHE_RUNS = 256
CACHE_BYTES = 64 * 1024 * 1024

Signature = tuple[tuple[str, int, int], ...]


@dataclass(frozen=True, slots=True)
class ReadRun:
    """One run as read: what it stands for, its view and its curves."""

    signature: Signature
    view_gz: bytes
    curves: OverlayRun
    stored: StoredResult | None  # the store's row when it was read (None: not stored yet)

    @property
    def size_bytes(self) -> int:
        curves = self.curves
        arrays = [curves.time_s, curves.time_ns, curves.torque_nm, curves.angle_deg]
        force = 0 if curves.force_n is None else curves.force_n.nbytes
        return len(self.view_gz) + sum(a.nbytes for a in arrays) + force

    @property
    def part_id(self) -> str | None:
        if self.stored is not None and self.stored.result.part_id:
            return self.stored.result.part_id
        result = self.curves.result
        return result.part_id if result is not None and result.part_id else None


class RunCache:
    """Runs by (station, run id), least recently asked for first out."""

    def __init__(self, max_runs: int = CACHE_RUNS, max_bytes: int = CACHE_BYTES) -> None:
        self.max_runs = max_runs
        self.max_bytes = max_bytes
        self._lock = threading.Lock()
        self._runs: OrderedDict[tuple[str, int], ReadRun] = OrderedDict()
        self._bytes = 0
        self.hits = 0
        self.misses = 0

    def get(self, key: tuple[str, int], signature: Signature) -> ReadRun | None:
        """The run kept for ``key`` when it stands for ``signature`` (its files unchanged)."""
        with self._lock:
            found = self._runs.get(key)
            if found is None or found.signature != signature:
                self.misses += 1
                return None
            self._runs.move_to_end(key)
            self.hits += 1
            return found

    def put(self, key: tuple[str, int], run: ReadRun) -> None:
        with self._lock:
            old = self._runs.pop(key, None)
            if old is not None:
                self._bytes -= old.size_bytes
            if run.size_bytes > self.max_bytes:
                return  # larger than the whole cache: sent, not kept
            self._runs[key] = run
            self._bytes += run.size_bytes
            while len(self._runs) > self.max_runs or self._bytes > self.max_bytes:
                _, dropped = self._runs.popitem(last=False)
                self._bytes -= dropped.size_bytes

    @property
    def size_bytes(self) -> int:
        with self._lock:
            return self._bytes

    def __len__(self) -> int:
        with self._lock:
            return len(self._runs)
