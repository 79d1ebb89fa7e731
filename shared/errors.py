"""The boltwatch exception tree.

::

    BoltwatchError
     ├── ConfigError        a configuration file is missing, unreadable or invalid
     ├── InputError         a data file (trace, recording, controller export) is unusable
     ├── CanDatabaseError   the DBC does not define what the contract needs
     └── TransportError     zenoh or the CAN bus could not be opened

Every error carries one line a person can act on: which file, which key,
what was expected. Boundaries re-raise with ``raise X from err``.
"""

from __future__ import annotations


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
