"""Folders and files: making a folder, and saying plainly why one cannot be made; a
symbolic link that never ends, found and named (:func:`symlink_loop`), and a path's real
path that does not fail on one (:func:`real_path`); an ``OSError`` in one line that names
its file; a file or folder fsynced by its path; a small text or JSON file replaced
atomically."""

from __future__ import annotations

import contextlib
import errno
import json
import os
import tempfile
from pathlib import Path
from typing import Any

from shared.errors import BoltwatchError


class FolderError(BoltwatchError):
    """A folder cannot be made; the message says why (no path: the caller names it)."""


#: what a symbolic link that never ends is called in an error's line
SYMLINK_LOOP = "is a symlink loop"


def make_folder(folder: Path) -> Path:
    """``folder`` with its parents, made if missing; FolderError saying why it cannot be."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except FileExistsError as err:
        if symlink_loop(folder) is not None:
            raise FolderError(loop_text(folder)) from err
        raise FolderError("is a file, expected a folder") from err
    except NotADirectoryError as err:
        blocking = next((p for p in folder.parents if p.exists() and not p.is_dir()), None)
        why = f"{blocking} is a file, not a folder" if blocking else "a part of it is a file"
        raise FolderError(f"cannot be made: {why}") from err
    except OSError as err:
        raise FolderError(f"cannot be made: {err.strerror}") from err
    return folder


def symlink_loop(path: Path) -> Path | None:
    """The symbolic link on the way to ``path``, or ``path`` itself, that never ends (a link
    to itself, or round a circle of links); None: none does."""
    if not _loops(path):
        return None
    return next((way for way in (*reversed(path.parents), path) if _loops(way)), path)


def loop_text(path: Path) -> str:
    """Why ``path`` cannot be reached, for a line that names ``path`` before it: ``is a
    symlink loop``, or which link on its way is."""
    link = symlink_loop(path)
    return SYMLINK_LOOP if link in (None, path) else f"{link} {SYMLINK_LOOP}"


def real_path(path: Path) -> Path:
    """``path`` absolute, its symbolic links followed (as :meth:`Path.resolve`), and left as
    it is from a link that never ends (where Python 3.11's ``resolve`` raises RuntimeError):
    what reads the path then names the loop."""
    return Path(os.path.realpath(path))


def _loops(path: Path) -> bool:
    try:
        os.stat(path)
    except OSError as err:
        return err.errno == errno.ELOOP
    return False


def describe_os_error(err: OSError, path: Path | None) -> str:
    """``<file>: <errno text> (<ERRNO>)``, e.g. ``a.mcap: No space left on device (ENOSPC)``."""
    where = err.filename if err.filename is not None else (path or "?")
    code = errno.errorcode.get(err.errno, str(err.errno)) if err.errno is not None else "?"
    return f"{where}: {err.strerror or err} ({code})"


def fsync_path(path: Path) -> None:
    """fsync the file or folder at ``path``: a file's bytes, or a folder's names (the files
    just created or renamed in it), on the disk."""
    handle = os.open(path, os.O_RDONLY)
    try:
        os.fsync(handle)
    finally:
        os.close(handle)


def write_json_atomically(path: Path, document: Any) -> None:
    """Replace ``path`` by ``document`` as JSON (:func:`write_text_atomically`)."""
    write_text_atomically(path, json.dumps(document))


def write_text_atomically(path: Path, text: str) -> None:
    """Replace ``path`` by ``text`` (UTF-8), whole or not at all: a temporary file in the
    same folder (mode 0600), fsync, rename, fsync of the folder (after a crash: the old or
    the new)."""
    folder = path.parent
    folder.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", dir=folder)
    try:
        with os.fdopen(handle, "w", encoding="utf-8") as stream:
            stream.write(text)
            stream.flush()
            os.fsync(stream.fileno())
        os.replace(temporary, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(temporary)
        raise
    fsync_path(folder)
