"""What the bridge counts since its process started, as the ``BridgeStats`` it publishes.

Written by the link thread only; read once a second by the stats thread (a
torn read of two counters is one second old at worst, never wrong for long).
A fault of the link or of a message is counted here and logged once per kind
(:class:`~shared.runtime.log_limit.RateLimitedLog`), never raised: ``boltwatch status``
shows the counters that are not zero.
"""

from __future__ import annotations

import dataclasses
import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from shared.contract import BridgeStats, ControllerAlarm
from shared.quality import cut_text
from shared.runtime import RateLimitedLog

LOG = logging.getLogger(__name__)

#: the kinds of faults, each logged once then at most every 10 s
FAULT_KINDS = (
    "garbage",
    "bad message",
    "refused value",
    "controller error",
    "link",
    "trace",
    "run id",
    "repeat",
    "epoch",
    "clock",
)


@dataclass
class BridgeCounts:
    """The counters of :class:`~shared.contract.messages.BridgeStats` and the link's state."""

    station: str
    controller: str  # "host:port"
    started_ns: int = field(default_factory=time.time_ns)
    connected: bool = False
    result_revision: int | None = None
    connects: int = 0
    link_drops: int = 0
    keep_alives_sent: int = 0
    results: int = 0
    results_filled: int = 0
    repeated_results: int = 0
    results_without_traces: int = 0
    traces: int = 0
    traces_without_result: int = 0
    garbage_bytes: int = 0
    bad_messages: int = 0
    refused_values: int = 0
    controller_errors: int = 0
    last_tightening_id: int | None = None
    last_error: str | None = None
    traces_refused: int = 0
    results_given_up: int = 0
    epochs: int = 0
    clock_refused: int = 0
    trace_reading: str | None = None
    active_alarm: ControllerAlarm | None = None
    _logs: dict[str, RateLimitedLog] = field(default_factory=dict)

    def fault(self, kind: str, text: str, level: int = logging.WARNING) -> None:
        """Log a fault of ``kind`` (rate-limited per kind) and keep it as the last error."""
        self.last_error = cut_text(text)
        self.note(kind, text, level)

    def note(self, kind: str, text: str, level: int = logging.INFO) -> None:
        """Log what is no fault (a repeat the controller sent) once per kind, rate-limited."""
        log = self._logs.get(kind)
        if log is None:
            log = self._logs[kind] = RateLimitedLog(LOG, level)
        log("%s", text)

    def stats(self, clock_ns: Callable[[], int] = time.time_ns) -> BridgeStats:
        """The counters as the message, each field of :class:`BridgeStats` by its name here."""
        values = {name: getattr(self, name) for name in _STATS_FIELDS}
        return BridgeStats(time_ns=clock_ns(), **values)


#: the fields of BridgeStats these counters give (all but the time it is sent)
_STATS_FIELDS = tuple(
    field.name for field in dataclasses.fields(BridgeStats) if field.name != "time_ns"
)
