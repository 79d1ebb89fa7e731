"""Open Protocol time stamps: ``YYYY-MM-DD:HH:MM:SS``, the controller's local time.

Messages keep the controller's text as it came; :func:`timestamp_ns` turns it
into integer nanoseconds since the epoch given the controller's time zone
(controllers send local time and say nothing of their zone: UTC unless the
bridge's configuration says otherwise).
"""

from __future__ import annotations

import datetime as dt
from typing import Final

TIMESTAMP_FORMAT: Final = "%Y-%m-%d:%H:%M:%S"
TIMESTAMP_CHARS: Final = 19


def parse_timestamp(text: str) -> dt.datetime:
    """The naive local date-time of ``text``; ValueError naming what is wrong."""
    if len(text) != TIMESTAMP_CHARS:
        raise ValueError(f"'{text}' is not YYYY-MM-DD:HH:MM:SS")
    try:
        return dt.datetime.strptime(text, TIMESTAMP_FORMAT)
    except ValueError:
        raise ValueError(f"'{text}' is not a date and time that exists") from None


def timestamp_ns(text: str, tz: dt.tzinfo = dt.UTC) -> int:
    """Nanoseconds since the epoch of the controller's local time ``text`` in zone ``tz``."""
    moment = parse_timestamp(text).replace(tzinfo=tz)
    return int(moment.timestamp()) * 1_000_000_000


def format_timestamp(time_ns: int, tz: dt.tzinfo = dt.UTC) -> str:
    """The controller text of ``time_ns`` (whole seconds) in zone ``tz``."""
    moment = dt.datetime.fromtimestamp(time_ns // 1_000_000_000, tz)
    return moment.strftime(TIMESTAMP_FORMAT)
