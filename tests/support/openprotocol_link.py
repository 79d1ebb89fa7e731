"""One integrator's link to the test controller: its state, how writes are cut, and the
extra data of a MID 0900 subscription.

The MID 0008 / MID 0009 extra data for MID 0900 follows Open Protocol Specification R2.8.0,
5.27.1.1 Table 158 and 5.27.1.2 Table 159: send alternative (1 digit; 0 = only new data),
a time stamp identifier (19) and an index identifier (10), unused and sent as spaces or
zeros, then the number of trace types (2) and each trace type (3 digits: 001 angle, 002
torque); unsubscribing names the number of trace types and each type, 999 for all. The
specification's own subscription example has 35 characters of extra data (one type); its
MID 0008 example in 5.2.7 has 39 ("020010020" after the 30: two types and one more digit),
so what follows the listed types is ignored. An answer "MID 0004 Error 78" refuses a send
alternative or a trace type the controller does not have.
"""

from __future__ import annotations

import random
import socket
from collections import deque
from dataclasses import dataclass, field
from typing import Literal

from tests.support.openprotocol_messages import Error
from tests.support.openprotocol_traces import ANGLE_TRACE, TORQUE_TRACE
from tests.support.openprotocol_wire import MessageReader

WriteMode = Literal["whole", "coalesced", "bytewise", "random"]
TRACE_TYPES = (ANGLE_TRACE, TORQUE_TRACE)


@dataclass
class InFlight:
    """A MID 0061 sent and not yet acknowledged."""

    tightening_id: int
    wire: bytes
    sends: int
    deadline_s: float


@dataclass
class Link:
    """The state of one connected integrator."""

    sock: socket.socket
    last_heard_s: float
    reader: MessageReader = field(default_factory=MessageReader)
    started: bool = False
    result_no_ack: bool = False
    trace_types: list[int] = field(default_factory=list)
    results_due: deque[int] = field(default_factory=deque)
    in_flight: InFlight | None = None
    traces_unacknowledged: deque[tuple[int, int]] = field(default_factory=deque)
    outbox: list[bytes] = field(default_factory=list)
    ending: str | None = None
    problems_seen: int = 0


def writes(chunks: list[bytes], mode: WriteMode, rng: random.Random) -> list[bytes]:
    """What each TCP send carries: a message, a turn's messages, a byte, or random cuts."""
    if mode == "whole":
        return chunks
    data = b"".join(chunks)
    if mode == "coalesced":
        return [data] if data else []
    if mode == "bytewise":
        return [data[i : i + 1] for i in range(len(data))]
    pieces: list[bytes] = []
    start = 0
    while start < len(data):
        end = start + rng.randint(1, 97)
        pieces.append(data[start:end])
        start = end
    return pieces


def trace_subscription(extra: str) -> list[int] | Error:
    """The trace types a MID 0008 for MID 0900 asks for, or the error to answer."""
    if not extra.strip():
        return list(TRACE_TYPES)  # nothing asked: every trace the controller has
    if extra[0] != "0":
        return Error.SUBSCRIPTION_DATA_UNSUPPORTED  # only new data is sent
    types = _trace_types(extra[30:])
    if isinstance(types, Error):
        return types
    if not types or any(t not in TRACE_TYPES for t in types):
        return Error.SUBSCRIPTION_DATA_UNSUPPORTED
    return types


def trace_unsubscription(extra: str, subscribed: list[int]) -> list[int] | Error:
    """The trace types left after a MID 0009 for MID 0900, or the error to answer."""
    if not extra.strip():
        return []
    types = _trace_types(extra)
    if isinstance(types, Error):
        return types
    if 999 in types:
        return []
    if any(t not in subscribed for t in types):
        return Error.SUBSCRIPTION_MISSING
    return [t for t in subscribed if t not in types]


def _trace_types(text: str) -> list[int] | Error:
    if len(text) < 2 or not text[:2].isdigit():
        return Error.INVALID_DATA
    count = int(text[:2])
    codes = [text[2 + 3 * i : 5 + 3 * i] for i in range(count)]
    if any(len(code) != 3 or not code.isdigit() for code in codes):
        return Error.INVALID_DATA
    return [int(code) for code in codes]
