"""What an operating-system error means, in one line that names the path.

:mod:`services.cli.main` turns every ``OSError`` a command lets through into
``boltwatch COMMAND: <path>: <why>``, for example::

    boltwatch export: /x/y.csv: folder /x does not exist
    boltwatch inspect: out.png/run.png: out.png is a file, not a folder
    boltwatch recover: run.mcap --out /mnt/usb: is a folder, not a file

The cause is read from ``errno`` and, where that is ambiguous (``ENOENT``:
is the file or a folder on its way missing?), from the file system.

Also here: whether standard output's reader has gone away (``boltwatch
predict ... | head -1``), which is how a pipe ends, not an error.
"""

from __future__ import annotations

import errno
import os
import select
import sys
from pathlib import Path

#: why, for the errno values a person meets on a command line
REASONS = {
    errno.EISDIR: "is a folder, not a file",
    errno.EACCES: "permission denied",
    errno.EPERM: "operation not permitted",
    errno.ENOSPC: "no space left on device",
    errno.EROFS: "read-only file system",
    errno.ENAMETOOLONG: "name too long",
    errno.EFBIG: "file too large (a file size limit was reached)",
    errno.EDQUOT: "disk quota exceeded",
    errno.EIO: "input/output error",
    errno.ELOOP: "too many symbolic links (a link loop?)",
}


def os_error_line(err: OSError) -> str:
    """``<path>: <why>`` (``<why>`` alone when the error names no path)."""
    if err.filename is None or isinstance(err.filename, int):
        return _reason(err, None)
    path = Path(os.fsdecode(err.filename))
    if err.filename2 is not None:
        other = os.fsdecode(err.filename2)
        return f"{path} -> {other}: {_reason(err, None)}"
    return f"{path}: {_reason(err, path)}"


def _reason(err: OSError, path: Path | None) -> str:
    if path is not None and err.errno in (errno.ENOENT, errno.ENOTDIR):
        in_the_way = _file_in_the_way(path)
        if in_the_way is not None and in_the_way != path:
            return f"{in_the_way} is a file, not a folder"
        if err.errno == errno.ENOTDIR:
            return "is a file, not a folder"
        missing = _first_missing_folder(path)
        return f"folder {missing} does not exist" if missing else "file not found"
    if path is not None and err.errno == errno.EEXIST:  # mkdir where a file is
        not_a_folder = path.exists() and not path.is_dir()
        return "already exists and is not a folder" if not_a_folder else "already exists"
    if err.errno in REASONS:
        return REASONS[err.errno]
    return err.strerror or type(err).__name__


def _first_missing_folder(path: Path) -> Path | None:
    """The outermost folder on the way to ``path`` that does not exist, if any."""
    for folder in reversed(path.parents):
        if not folder.exists():
            return folder
    return None


def _file_in_the_way(path: Path) -> Path | None:
    """The first thing on the way to ``path`` (or ``path`` itself) that is there but is not a
    folder, where a folder is needed."""
    for candidate in (*reversed(path.parents), path):
        if candidate.exists() and not candidate.is_dir():
            return candidate
    return None


def stdout_reader_gone() -> bool:
    """True when standard output is a pipe whose reading end is closed (``| head -1`` has
    read its line): the kernel flags such a pipe POLLERR for the writer."""
    try:
        fd = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):  # replaced (tests) or closed
        return False
    poller = select.poll()
    poller.register(fd, select.POLLOUT)
    return any(events & select.POLLERR for _, events in poller.poll(0))


def silence_stdout() -> None:
    """Point standard output at /dev/null, so that Python's last flush at exit does not
    fail again on the closed pipe (the recipe of Python's ``signal`` documentation)."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, sys.stdout.fileno())
    finally:
        os.close(devnull)
