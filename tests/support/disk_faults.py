"""Real disk faults for tests: a size-limited tmpfs, filled up; a read-only bind mount.

Mounting needs root (or CAP_SYS_ADMIN); without it the test that asked is
skipped with the reason. Every mount is undone when its context ends.
"""

from __future__ import annotations

import contextlib
import errno
import os
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest

_CHUNK = b"\0" * 65536


def _mount(*args: str) -> None:
    result = subprocess.run(["mount", *args], capture_output=True, text=True, check=False)
    if result.returncode != 0:
        pytest.skip(f"cannot mount here (mount {' '.join(args)}): {result.stderr.strip()}")


def _unmount(path: Path) -> None:
    subprocess.run(["umount", "-l", str(path)], capture_output=True, check=False)


@contextlib.contextmanager
def tmpfs(path: Path, size_bytes: int) -> Iterator[Path]:
    """A tmpfs of ``size_bytes`` mounted on ``path`` (created); unmounted afterwards."""
    path.mkdir(parents=True, exist_ok=True)
    _mount("-t", "tmpfs", "-o", f"size={size_bytes}", "tmpfs", str(path))
    try:
        yield path
    finally:
        _unmount(path)


@contextlib.contextmanager
def read_only(path: Path) -> Iterator[Path]:
    """``path`` bind-mounted read-only on itself until the context ends."""
    _mount("--bind", str(path), str(path))
    try:
        _mount("-o", "remount,bind,ro", str(path))
        yield path
    finally:
        _unmount(path)


def fill_up(folder: Path) -> Path:
    """Write a filler file into ``folder`` until its file system is full; the filler."""
    filler = folder / "filler.bin"
    with filler.open("wb", buffering=0) as handle:
        for block in (_CHUNK, _CHUNK[:4096], _CHUNK[:1]):
            while True:
                try:
                    handle.write(block)
                except OSError as err:
                    if err.errno != errno.ENOSPC:
                        raise
                    break
    os.sync()
    return filler
