"""How full the recordings' file system is, as ``df`` counts it.

``df``'s ``Use%`` is used / (used + available): the blocks a root-only
reserve keeps back count as neither, so 100 % is the point where the
recorder (not root) can write no more. :func:`disk_usage_of` measures it
with :func:`shutil.disk_usage` (``statvfs``), or any function of that shape:
what a test gives it is what the planner sees.
"""

from __future__ import annotations

import math
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

#: what measures a folder's file system: shutil.disk_usage's shape (total, used, free)
Measure = Callable[[Path], Any]


@dataclass(frozen=True, slots=True)
class DiskUsage:
    """The recordings' file system: bytes used, and bytes still available to write."""

    used_bytes: int
    free_bytes: int

    @property
    def capacity_bytes(self) -> int:
        return self.used_bytes + self.free_bytes

    @property
    def used_pct(self) -> float:
        return 100.0 * self.used_bytes / self.capacity_bytes if self.capacity_bytes else 0.0

    def bytes_over(self, max_used_pct: float) -> int:
        """Bytes to free to be at most ``max_used_pct`` used (0: it is already)."""
        allowed_bytes = max_used_pct / 100.0 * self.capacity_bytes
        return max(0, math.ceil(self.used_bytes - allowed_bytes))


def disk_usage_of(folder: Path, measure: Measure = shutil.disk_usage) -> DiskUsage:
    """The file system of ``folder`` now."""
    measured = measure(folder)
    return DiskUsage(used_bytes=int(measured.used), free_bytes=int(measured.free))
