"""What ``boltwatch status`` and the line's page show of a station's spool (store and forward).

From the latest :class:`~shared.contract.messages.SpoolStats` of each spooling
source on ``boltwatch/<st>/spool`` (once a second from the station's
acquisition or bridge): what waits for the line's recorder (runs, samples,
bytes, and how full the spool is), the oldest run not delivered and how old
its oldest message is, how fast it is sent again, and what it had to drop.
An alert when the spool is past :data:`FULL_ALERT` of its bound or dropped
anything: past the bound the oldest samples go (never a result or a summary).
Collected by :mod:`shared.line_status.station_status`, printed by
:mod:`services.cli.station_status_text`, drawn by the line's page.
"""

from __future__ import annotations

from dataclasses import dataclass

from shared.contract import SpoolStats, channels, decode

_NS = 1_000_000_000

#: the topic this module reads
TOPIC = channels.SPOOL.topic
#: a spool this full (of its ``max_bytes``) raises the alert
FULL_ALERT = 0.8


@dataclass(frozen=True)
class SpoolStatus:
    """One spool of a station (its acquisition's, or its controller bridge's)."""

    source: str
    messages: int  # waiting for the recorder's acknowledgement
    runs: int
    samples: int
    bytes: int
    max_bytes: int
    full_pct: float
    oldest_run_id: int | None  # the oldest run not delivered whole
    oldest_age_s: float | None  # how long its oldest message has waited
    resend_per_s: float
    dropped_samples: int
    dropped_messages: int
    acknowledged_age_s: float | None  # since the recorder's last acknowledgement
    alert: str | None  # why the spool needs a look (full, dropped); None: it does not
    age_s: float  # since these counters were received


def take(latest: dict[str, tuple[SpoolStats, int]], payload: bytes, received_ns: int) -> None:
    """One message of :data:`TOPIC` into ``latest`` (by source; InputError: not a valid one)."""
    stats = decode(SpoolStats, payload)
    latest[stats.source] = (stats, received_ns)


def spool_status(latest: dict[str, tuple[SpoolStats, int]], now_ns: int) -> list[SpoolStatus]:
    """Every spool heard in the window, by source."""
    return [
        _status(stats, received_ns, now_ns) for _, (stats, received_ns) in sorted(latest.items())
    ]


def _status(stats: SpoolStats, received_ns: int, now_ns: int) -> SpoolStatus:
    full = stats.bytes / stats.max_bytes if stats.max_bytes else 0.0
    alerts = []
    if full >= FULL_ALERT:
        alerts.append(f"{100 * full:.0f} % full")
    if stats.dropped_samples or stats.dropped_messages:
        alerts.append(
            f"dropped {stats.dropped_samples} samples ({stats.dropped_messages} messages) "
            "to keep its bound"
        )
    return SpoolStatus(
        source=stats.source,
        messages=stats.messages,
        runs=stats.runs,
        samples=stats.samples,
        bytes=stats.bytes,
        max_bytes=stats.max_bytes,
        full_pct=round(100 * full, 1),
        oldest_run_id=stats.oldest_run_id,
        oldest_age_s=_age_s(stats.oldest_ns, stats.time_ns),
        resend_per_s=stats.resend_rate,
        dropped_samples=stats.dropped_samples,
        dropped_messages=stats.dropped_messages,
        acknowledged_age_s=_age_s(stats.acknowledged_ns, stats.time_ns),
        alert="; ".join(alerts) or None,
        age_s=round((now_ns - received_ns) / _NS, 3),
    )


def _age_s(then_ns: int | None, now_ns: int) -> float | None:
    return None if then_ns is None else round(max(0, now_ns - then_ns) / _NS, 3)


def spool_text(spool: SpoolStatus) -> str:
    """One line for a person."""
    if not spool.messages:
        waiting = "nothing waits for the recorder"
    else:
        oldest = "" if spool.oldest_run_id is None else f", oldest run {spool.oldest_run_id}"
        since = "" if spool.oldest_age_s is None else f" waiting {spool.oldest_age_s:.0f} s"
        waiting = f"{spool.runs} runs, {spool.samples} samples wait for the recorder{oldest}{since}"
    parts = [
        waiting,
        f"{_megabytes(spool.bytes)} of {_megabytes(spool.max_bytes)} ({spool.full_pct:.1f} %)",
    ]
    if spool.resend_per_s:
        parts.append(f"sending again {spool.resend_per_s:.0f}/s")
    if spool.acknowledged_age_s is None:
        parts.append("no acknowledgement from a recorder yet")
    elif spool.acknowledged_age_s > 5:
        parts.append(f"recorder silent for {spool.acknowledged_age_s:.0f} s")
    if spool.alert:
        parts.append(f"ALERT: {spool.alert}")
    return ", ".join(parts)


def _megabytes(count: int) -> str:
    return f"{count / 1e6:.1f} MB" if count < 1e9 else f"{count / 1e9:.2f} GB"
