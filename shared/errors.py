"""The boltwatch exception tree.

::

    BoltwatchError
     ├── ConfigError        a configuration file is missing, unreadable or invalid
     ├── InputError         a data file (trace, recording, controller export) is unusable
     ├── CanDatabaseError   the DBC does not define what the contract needs
     ├── TransportError     zenoh or the CAN bus could not be opened
     └── StoreError         the results store cannot be opened, read or written

Every error carries one line a person can act on: which file, which key,
what was expected. Boundaries re-raise with ``raise X from err``.

An ``OSError`` is not wrapped: the command line turns it into one line from
its ``filename`` and ``errno``. :func:`naming` makes sure it has a filename
(a write that fails on a full disk names none).
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator


class BoltwatchError(Exception):
    """Base of every error boltwatch raises on purpose."""


class ConfigError(BoltwatchError):
    """A configuration file is missing, unreadable or has a bad value."""


class InputError(BoltwatchError):
    """A data file given on the command line cannot be read as expected."""


class CanDatabaseError(BoltwatchError):
    """The CAN database lacks a message or signal of the contract."""


class TransportError(BoltwatchError):
    """A zenoh session or CAN bus could not be opened."""


class StoreError(BoltwatchError):
    """The results store cannot be opened, read or written (the text says which and why)."""


@contextlib.contextmanager
def naming(path: str | os.PathLike[str]) -> Iterator[None]:
    """An ``OSError`` raised inside that names no file is raised again naming ``path``."""
    try:
        yield
    except OSError as err:
        if err.filename is not None or err.errno is None:
            raise
        raise OSError(err.errno, err.strerror, os.fspath(path)) from err
