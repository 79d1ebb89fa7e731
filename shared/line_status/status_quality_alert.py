"""The newest active quality alert ``boltwatch status`` heard of a station.

From :class:`~shared.contract.messages.QualityAlert` on ``boltwatch/<st>/quality/alert``
(put by the recorder when a program's rolling Cpk or its NOKs go out of
bounds, and once more when they are back): each condition's (program, kind,
figure) latest word counts; the newest of those still active is shown, with
the number of conditions active. The recorder puts an alert once, when it
starts, and carries the alerts active now in its once-a-second
``RecorderStats`` (``quality_alerts``): a status listening later learns of
them there.
Collected by :mod:`shared.line_status.station_status`, printed by
:mod:`services.cli.station_status_text`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from shared.contract import QualityAlert, channels, decode

_NS = 1_000_000_000

#: the topic this module reads
TOPIC = channels.QUALITY_ALERT.topic


@dataclass
class QualitySeen:
    """The latest quality alert of each condition heard in the window."""

    latest: dict[tuple[int, str, str | None], QualityAlert] = field(default_factory=dict)

    def take(self, payload: bytes) -> None:
        """One message of :data:`TOPIC` (InputError: not a valid one)."""
        self._take(decode(QualityAlert, payload))

    def take_active(self, alerts: list[QualityAlert]) -> None:
        """The alerts a RecorderStats says are active now."""
        for alert in alerts:
            self._take(alert)

    def _take(self, alert: QualityAlert) -> None:
        condition = (alert.program_id, alert.kind, alert.figure)
        known = self.latest.get(condition)
        if known is None or alert.time_ns >= known.time_ns:
            self.latest[condition] = alert


@dataclass(frozen=True)
class ActiveQualityAlert:
    program_id: int
    kind: str  # cpk_low | nok_run | nok_rate
    figure: str | None  # torque | angle | preload (cpk_low); None for the NOK kinds
    value: float
    limit: float
    runs: int
    text: str
    active_alerts: int  # conditions active at the station (this one included)
    age_s: float  # since the result that started it ended


def quality_alert(seen: QualitySeen, now_ns: int) -> ActiveQualityAlert | None:
    """The newest active alert; None when none is active (or none was heard)."""
    active = [alert for alert in seen.latest.values() if alert.active]
    if not active:
        return None
    newest = max(active, key=lambda alert: alert.time_ns)
    return ActiveQualityAlert(
        program_id=newest.program_id,
        kind=newest.kind,
        figure=newest.figure,
        value=newest.value,
        limit=newest.limit,
        runs=newest.runs,
        text=newest.text,
        active_alerts=len(active),
        age_s=round((now_ns - newest.time_ns) / _NS, 3),
    )


def quality_text(alert: ActiveQualityAlert | None) -> str:
    """One line for a person."""
    if alert is None:
        return "none active in the window"
    more = f" (+{alert.active_alerts - 1} more active)" if alert.active_alerts > 1 else ""
    return f"{alert.kind}: {alert.text}, {alert.age_s:.1f} s ago{more}"
