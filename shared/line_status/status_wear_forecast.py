"""The tools ``boltwatch status`` heard forecast due for service soon, at a station.

From the recorder: each :class:`~shared.contract.messages.WearForecast` on
``boltwatch/<st>/wear/forecast`` (put once per tool and horizon, when a tool is
forecast to reach its service threshold within it), and the forecasts its
once-a-second ``RecorderStats`` carries (``wear_forecasts``: the tools forecast
due within its largest horizon now): a status that listens later learns of them
there, and one the recorder no longer carries (the tool serviced, or due now:
its ``WearAlert``) is dropped. The soonest first. Collected by
:mod:`shared.line_status.station_status`, printed by
:mod:`services.cli.station_status_text`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from datetime import UTC, datetime

from shared.contract import WearForecast, channels, decode

_NS = 1_000_000_000

#: the topic this module reads
TOPIC = channels.WEAR_FORECAST.topic


@dataclass
class ForecastsSeen:
    """The latest forecast of each tool heard in the window."""

    latest: dict[int, WearForecast] = field(default_factory=dict)

    def take(self, payload: bytes) -> None:
        """One message of :data:`TOPIC` (InputError: not a valid one)."""
        told = decode(WearForecast, payload)
        known = self.latest.get(told.tool_id)
        if known is None or told.time_ns >= known.time_ns:
            self.latest[told.tool_id] = told

    def take_current(self, forecasts: list[WearForecast]) -> None:
        """The forecasts a RecorderStats carries now: they are all there is."""
        self.latest = {told.tool_id: told for told in forecasts}


@dataclass(frozen=True)
class DueSoon:
    """A tool forecast due for service soon."""

    tool_id: int
    due_ns: int
    early_ns: int
    late_ns: int | None
    production_days: float
    runs_left: int
    service_by_ns: int | None  # the last shift change before the early end
    horizon_days: float
    in_days: float  # calendar days from now to due_ns


def due_soon(seen: ForecastsSeen, now_ns: int) -> list[DueSoon]:
    """The forecasts heard, the soonest first."""
    return [
        DueSoon(
            tool_id=told.tool_id,
            due_ns=told.due_ns,
            early_ns=told.early_ns,
            late_ns=told.late_ns,
            production_days=told.production_days,
            runs_left=told.runs_left,
            service_by_ns=told.service_by_ns,
            horizon_days=told.horizon_days,
            in_days=round((told.due_ns - now_ns) / (86_400 * _NS), 2),
        )
        for told in sorted(seen.latest.values(), key=lambda told: told.due_ns)
    ]


def _utc(time_ns: int | None) -> str:
    if time_ns is None:
        return "later"
    return f"{datetime.fromtimestamp(time_ns / _NS, UTC):%Y-%m-%d %H:%M}"


def due_soon_text(soon: list[DueSoon]) -> str:
    """One line for a person: the tool due soonest, and how many more."""
    if not soon:
        return "no tool forecast due within the recorder's horizon"
    first = soon[0]
    plan = f"; plan its service by {_utc(first.service_by_ns)}" if first.service_by_ns else ""
    more = f" (+{len(soon) - 1} more)" if len(soon) > 1 else ""
    return (
        f"tool {first.tool_id} due {_utc(first.due_ns)} UTC, in {first.production_days:.1f} "
        f"production days (80 %: {_utc(first.early_ns)} to {_utc(first.late_ns)}), "
        f"{first.runs_left} runs left{plan}{more}"
    )
