"""What a station's spool and the line's recorder say to each other (store and forward).

Re-exported by :mod:`shared.contract.messages`. Same rules as every message
there. Every message a spooling station puts toward the line carries, in its
zenoh attachment, ``<source>:<spool>:<seq>`` (:func:`seq_attachment`): the
publisher (``acquisition``, ``openprotocol``), its spool's id (a number drawn
when the spool file is made: a spool deleted and made again counts from 1
again, and the recorder must not take its numbers for ones it has) and the
number the spool gave the message, counting up from 1 across restarts. A
message sent again carries ``:again:<n>`` after it: ``n`` the number its
spool holds before it, so the recorder knows every number between is gone
(acknowledged already, or dropped to keep the spool's bound).

- :class:`SpoolAck` (the recorder, ``boltwatch/<st>/spool/ack``, once a second
  per spooling source): what it has written to disk and flushed; the station
  deletes it from its spool and sends again what is not acknowledged;
- :class:`SpoolStats` (the station, ``boltwatch/<st>/spool``, once a second):
  the spool's depth, what it sends again, what it had to drop;
- :class:`SpoolFiled` (never put on the line: the recorder writes it into its
  own files, last in each chunk): the numbers of one spool a file holds, which a
  restarted recorder reads so that what the station sends again of it is not
  filed twice.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated

from shared.contract.message_fields import WIRE_CONFIG, Count, StationId, TextRange, TimeNs

#: who spools: the service that publishes a station's messages toward the line
SpoolSource = Annotated[str, TextRange(32)]


#: the mark of a message sent again (not live)
AGAIN = "again"


@dataclass(frozen=True, slots=True)
class SeqMark:
    """What a spooled message's attachment says: whose, which number, live or sent again."""

    source: str
    spool_id: int
    seq: int
    #: sent again: the number the spool holds before it (0: none); every number between
    #: is gone from the spool (acknowledged, or dropped to keep its bound). None: live
    kept_before: int | None = None

    @property
    def again(self) -> bool:
        return self.kept_before is not None


def seq_attachment(source: str, spool_id: int, seq: int, kept_before: int | None = None) -> bytes:
    """The zenoh attachment of message ``seq`` of spool ``spool_id`` of ``source``; with
    ``kept_before`` (the number the spool holds before it, 0: none) it is sent again."""
    again = "" if kept_before is None else f":{AGAIN}:{kept_before}"
    return f"{source}:{spool_id}:{seq}{again}".encode("ascii")


def parse_seq_attachment(attachment: bytes | None) -> SeqMark | None:
    """What an attachment :func:`seq_attachment` made says; None for any other."""
    if not attachment or len(attachment) > 128:
        return None
    parts = attachment.decode("ascii", errors="replace").split(":")
    if len(parts) not in (3, 5) or not parts[0] or len(parts[0]) > 32:
        return None
    numbers = parts[1:3] + parts[4:]
    if not all(n.isascii() and n.isdigit() and len(n) <= 18 for n in numbers):
        return None
    if len(parts) == 5 and parts[3] != AGAIN:
        return None
    spool_id, seq = int(numbers[0]), int(numbers[1])
    kept_before = int(numbers[2]) if len(parts) == 5 else None
    if spool_id < 1 or seq < 1 or (kept_before is not None and kept_before >= seq):
        return None
    return SeqMark(parts[0], spool_id, seq, kept_before)


@dataclass(frozen=True, slots=True)
class SeqRange:
    """Spooled messages ``first`` to ``last`` of one source (inclusive)."""

    __pydantic_config__ = WIRE_CONFIG

    first: Count
    last: Count


@dataclass(frozen=True, slots=True)
class SpoolAck:
    """What the recorder holds, on disk, of one spooling source of a station."""

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    source: SpoolSource
    spool_id: Count
    time_ns: TimeNs
    through: Count  # every seq from 1 to it is written (or was gone from the spool)
    #: written ranges above ``through``: what came live while older messages wait to be
    #: sent again
    ranges: list[SeqRange] = field(default_factory=list)


@dataclass(frozen=True, slots=True)
class SpoolStats:
    """A station's spool, once a second: what waits for the line's recorder."""

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    source: SpoolSource
    spool_id: Count
    time_ns: TimeNs
    messages: Count  # waiting for the recorder's acknowledgement
    samples: Count  # samples among them
    runs: Count  # runs with a message among them
    bytes: Count  # the spool's file, on disk
    max_bytes: Count  # its bound
    oldest_seq: Count  # the oldest seq it still has (0: none)
    head_seq: Count  # the newest seq it gave
    oldest_run_id: Count | None  # the oldest run with a message not acknowledged
    oldest_ns: TimeNs | None  # when the oldest message waiting was put
    resent: Count  # messages sent again since the process started
    resend_rate: float  # messages sent again per second over the last second
    dropped_samples: Count  # samples dropped to keep the bound (the oldest first)
    dropped_messages: Count  # messages dropped to keep the bound
    acknowledged_ns: TimeNs | None  # when the last acknowledgement came (None: never)


@dataclass(frozen=True, slots=True)
class SpoolFiled:
    """The numbers of one spooling source a recording file holds (so far, in its chunks up
    to this one): written by the recorder into its files, never put on the line."""

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    source: SpoolSource
    spool_id: Count
    time_ns: TimeNs
    ranges: list[SeqRange] = field(default_factory=list)
