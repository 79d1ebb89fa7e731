"""What the recorder says of a tool's coming service: a forecast within a horizon.

Re-exported by :mod:`shared.contract.messages`. Same rules as every message
there. Beside :class:`~shared.contract.messages.WearAlert` (a tool past its
service threshold: due now), a :class:`WearForecast` says ahead of time that a
tool is forecast to reach its threshold within one of the recorder's
``recorder.wear_forecast_days`` horizons (:mod:`shared.wear.wear_forecast`: the
date from its intensity per production day, with an 80 % interval): put once
per tool and horizon between two services, on ``boltwatch/<st>/wear/forecast``
of the station whose run made it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated

from shared.contract.message_fields import (
    WIRE_CONFIG,
    Count,
    Id,
    NumberRange,
    StationId,
    TimeNs,
)

#: a horizon or a count of production days: from 0 to ten years
Days = Annotated[float, NumberRange(0.0, 3653.0)]
#: an intensity (Σ I_process, eq. 69): finite, from 0
Intensity = Annotated[float, NumberRange(0.0, 1.7976931348623157e308)]


@dataclass(frozen=True, slots=True)
class WearForecast:
    """A tool is forecast to come due for service within ``horizon_days`` (calendar days)."""

    __pydantic_config__ = WIRE_CONFIG

    station: StationId  # where the run that made the forecast ran
    tool_id: Id
    time_ns: TimeNs  # when the forecast was made
    horizon_days: Days  # the horizon it came within (recorder.wear_forecast_days)
    due_ns: TimeNs  # the forecast date of the threshold crossing
    early_ns: TimeNs  # its 80 % interval: the early end
    late_ns: TimeNs | None  # the late end (None: beyond two years at the slow end)
    production_days: Days  # production days from time_ns to due_ns
    runs_left: Count  # tightenings to the threshold at the recent intensity per run
    intensity_since_service: Intensity
    threshold: Intensity
    intensity_per_day: Intensity  # the tool's pace: intensity per production day
    runs_since_service: Count
    last_service_ns: TimeNs | None
    service_by_ns: TimeNs | None  # the last shift change before the early end: plan it there
