"""The recorder's forecasts of its tools' services: a ``WearForecast`` ahead of time.

After each run counted (:mod:`.wear_watch`), the tool's intensity since
service (kept from the rows added) is held against its pace and the plant's
calendar (:func:`shared.wear.forecast`); the pace is read from the ledger once
per production day and tool (and again after a service), so a run costs the
arithmetic only. A tool forecast to reach ``recorder.wear_service_threshold``
within one of ``recorder.wear_forecast_days`` (calendar days from now) gets a
:class:`~shared.contract.messages.WearForecast` on
``boltwatch/<station>/wear/forecast``, once per tool and horizon between two
services (a recorder started again says it once more). The latest forecast of
each tool due within the largest horizon is kept for ``RecorderStats``
(``wear_forecasts``), under the station of its newest run, until the tool is
due (then :class:`~shared.contract.messages.WearAlert` says it), serviced, or
forecast beyond every horizon.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime

from shared.contract import WearForecast
from shared.wear import ToolOutlook, WearLedger, forecast
from shared.wear.wear_since_service import ServiceInterval

LOG = logging.getLogger(__name__)

DAY_NS = 86_400 * 1_000_000_000


@dataclass(frozen=True, slots=True)
class _Pace:
    outlook: ToolOutlook | None
    day: int  # the production day it was read on
    last_service_ns: int | None


class WearForecasts:
    """Per tool: its pace read once a production day, its horizons said, its latest forecast."""

    def __init__(
        self,
        threshold: float,
        horizons_days: Sequence[float],
        say: Callable[[WearForecast], None],
    ) -> None:
        self._threshold = threshold
        self._horizons = sorted(set(horizons_days), reverse=True)
        self._say = say
        self._paces: dict[int, _Pace] = {}
        self._said: set[tuple[int, float, int | None]] = set()
        self._soon: dict[int, WearForecast] = {}

    def after_run(
        self, ledger: WearLedger, station: str, interval: ServiceInterval, now_ns: int
    ) -> None:
        """The tool's forecast after a run of it at ``station``; said when it came within a
        horizon."""
        tool_id = interval.tool_id
        if not self._horizons:
            return
        if interval.intensity >= self._threshold:
            self._soon.pop(tool_id, None)  # due: the WearAlert says it
            return
        pace = self._pace(ledger, tool_id, interval.last_service_ns, now_ns)
        outlook = pace.outlook
        told = forecast(
            tool_id,
            outlook.pace if outlook else None,
            outlook.calendar if outlook else None,
            interval.intensity,
            self._threshold,
            now_ns,
        )
        if told.state != "forecast" or told.due_ns is None or told.early_ns is None:
            self._soon.pop(tool_id, None)
            return
        within = [h for h in self._horizons if told.due_ns - now_ns <= h * DAY_NS]
        if not within:
            self._soon.pop(tool_id, None)
            return
        said = None
        for horizon in within:
            message = WearForecast(
                station=station,
                tool_id=tool_id,
                time_ns=now_ns,
                horizon_days=horizon,
                due_ns=told.due_ns,
                early_ns=told.early_ns,
                late_ns=told.late_ns,
                production_days=told.production_days or 0.0,
                runs_left=told.runs_left or 0,
                intensity_since_service=interval.intensity,
                threshold=self._threshold,
                intensity_per_day=told.per_day or 0.0,
                runs_since_service=interval.runs,
                last_service_ns=interval.last_service_ns,
                service_by_ns=told.service_by_ns,
            )
            said = said or message  # the largest horizon it is within
            key = (tool_id, horizon, interval.last_service_ns)
            if key not in self._said:
                self._said.add(key)
                LOG.warning(
                    "tool %d forecast due for service within %g days: %s UTC (80 %%: %s to %s), "
                    "%d runs left",
                    tool_id,
                    horizon,
                    _utc(told.due_ns),
                    _utc(told.early_ns),
                    _utc(told.late_ns),
                    message.runs_left,
                )
                self._say(message)
        if said is not None:
            self._soon[tool_id] = said

    def soon(self, station: str) -> list[WearForecast]:
        """The latest forecasts due within the largest horizon, of the tools whose newest run
        was at ``station``, the soonest first."""
        found = [told for told in self._soon.values() if told.station == station]
        return sorted(found, key=lambda told: told.due_ns)

    def _pace(
        self, ledger: WearLedger, tool_id: int, last_service_ns: int | None, now_ns: int
    ) -> _Pace:
        kept = self._paces.get(tool_id)
        day = now_ns // DAY_NS
        if kept is not None and kept.outlook is not None and kept.outlook.calendar is not None:
            day = kept.outlook.calendar.day_of(now_ns)
        if kept is None or kept.day != day or kept.last_service_ns != last_service_ns:
            outlook = ledger.outlook(tool_id, now_ns)
            if outlook is not None and outlook.calendar is not None:
                day = outlook.calendar.day_of(now_ns)
            kept = _Pace(outlook, day, last_service_ns)
            self._paces[tool_id] = kept
        return kept


def _utc(time_ns: int | None) -> str:
    if time_ns is None:
        return "later"
    return f"{datetime.fromtimestamp(time_ns / 1e9, UTC):%Y-%m-%d %H:%M}"
