"""``argparse`` value types that refuse impossible numbers while the command line is parsed.

A long-running command (``boltwatch serve``, ``up``, ``status``) must refuse
a bad value before it opens a bus or a session, not after: with these as an
option's ``type``, argparse ends the command at once with its usage line
and, e.g.::

    boltwatch serve acquisition: error: argument --stats-interval-s: expected
    seconds, a number above 0 and at most 86400 (got 'nan')

and exit status 2. Every type refuses nan and infinities; the ranges are
what each quantity can physically or technically be.

Light imports only: the service ``arguments`` modules import this for
``boltwatch --help``.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable

#: the longest interval or timeout a command takes, in seconds (one day)
MAX_SECONDS = 86_400.0


def _number(text: str, expected: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected {expected} (got {text!r})")
    return value


def float_in(
    low: float, high: float, unit: str, low_allowed: bool = True
) -> Callable[[str], float]:
    """A finite number from ``low`` (or just above it) to ``high``, in ``unit``."""
    above = "from" if low_allowed else "above"
    expected = f"a number {above} {low:g} up to {high:g} {unit}".rstrip()

    def parse(text: str) -> float:
        value = _number(text, expected)
        if value > high or value < low or (value == low and not low_allowed):
            raise argparse.ArgumentTypeError(f"expected {expected} (got {text!r})")
        return value

    parse.__name__ = "number"
    return parse


def int_in(low: int, high: int, what: str = "a whole number") -> Callable[[str], int]:
    """A whole number from ``low`` to ``high``."""
    expected = f"{what} from {low} to {high}"

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {expected} (got {text!r})") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"expected {expected} (got {text!r})")
        return value

    parse.__name__ = "whole number"
    return parse


#: an interval or a timeout: seconds above 0, at most a day
seconds = float_in(0.0, MAX_SECONDS, "seconds", low_allowed=False)

#: a TCP/UDP port to listen on
port_number = int_in(1, 65535, "a port number")
