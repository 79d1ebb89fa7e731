"""What the simulated Open Protocol controller counts, and the line it logs them in."""

from __future__ import annotations

from dataclasses import dataclass, fields


@dataclass
class ControllerCounters:
    """Counts since the controller started (one process)."""

    tightenings: int = 0
    ok: int = 0
    nok: int = 0
    alarms: int = 0
    links: int = 0  # integrators accepted
    links_refused: int = 0  # a connection beyond the controller's limit
    drops_ack: int = 0  # links dropped: a 0061 never acknowledged (after the re-sends)
    drops_silent: int = 0  # links dropped: nothing heard for link_timeout_s
    drops_stopped: int = 0  # links ended by the integrator's 0003
    drops_closed: int = 0  # links the integrator closed (or a read/write failed)
    results_pushed: int = 0  # 0061 sent (first time)
    results_resent: int = 0  # 0061 sent again for want of a 0062
    results_acked: int = 0  # 0062 received for the 0061 awaiting it
    traces_pushed: int = 0  # 0900 sent
    old_results_served: int = 0  # 0065 sent
    keep_alives: int = 0  # 9999 received
    errors_sent: int = 0  # 0004 sent (refusals: revision, unknown MID, unknown id, ...)
    bad_messages: int = 0  # messages whose content the codec refused
    garbage_bytes: int = 0  # bytes the frame reader skipped
    bad_frames: int = 0  # frames with an impossible length

    def line(self) -> str:
        """``name value`` of every count that is not zero, for the log."""
        parts = [f"{f.name} {getattr(self, f.name)}" for f in fields(self) if getattr(self, f.name)]
        return ", ".join(parts) or "nothing yet"
