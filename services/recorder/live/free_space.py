"""The free-space guard: no new run file below a reserve of free space on the recordings disk.

A full disk cuts a file in the middle of a run; the guard keeps a reserve
(``recorder.free_space_reserve_bytes``, by default the largest a run file
may grow to) so that never happens to the files already open: below it, no
new file is opened (:meth:`FreeSpace.check` raises :class:`LowFreeSpaceError`,
an ``OSError`` of ``ENOSPC``), while the files open now are finished whole. The
recorder treats it as the disk failing (:mod:`.recorder`): the run's messages
are dropped and counted, one ERROR naming the free space and the key,
``recording: false`` and the reason in ``RecorderStats`` (``boltwatch status``,
the line's page), and the next run (or a retry every few seconds) records again
once there is room. ``statvfs`` is one system call, made only when a file is
to be opened.
"""

from __future__ import annotations

import errno
import os
from pathlib import Path

#: the station file's key that sets the reserve
RESERVE_KEY = "recorder.free_space_reserve_bytes"


class LowFreeSpaceError(OSError):
    """Free space below the reserve: no new run file (``errno`` ENOSPC, the folder named)."""


class FreeSpace:
    """The free space of the file system holding ``folder``, against ``reserve_bytes``."""

    def __init__(self, folder: Path, reserve_bytes: int) -> None:
        self.folder = folder
        self.reserve_bytes = reserve_bytes

    def free_bytes(self) -> int:
        """Bytes an unprivileged writer may still use on the folder's file system."""
        folder = self.folder  # made with the first file: its nearest existing parent till then
        while not folder.exists() and folder.parent != folder:
            folder = folder.parent
        found = os.statvfs(folder)
        return found.f_bavail * found.f_frsize

    def check(self) -> None:
        """Raise :class:`LowFreeSpaceError` when the free space is below the reserve."""
        if self.reserve_bytes <= 0:
            return
        free_bytes = self.free_bytes()
        if free_bytes < self.reserve_bytes:
            raise LowFreeSpaceError(
                errno.ENOSPC,
                f"free space {_mb(free_bytes)} is below the reserve of "
                f"{_mb(self.reserve_bytes)} ({RESERVE_KEY}): no new run file until there is room",
                str(self.folder),
            )


def _mb(size_bytes: int) -> str:
    return f"{size_bytes / 1e6:.1f} MB"
