"""boltwatch status: the tools the recorder forecasts due soon, from its alerts and its stats."""

from __future__ import annotations

import json
from typing import Any

from services.cli.station_status_text import format_report
from shared.contract import RecorderStats, WearForecast, channels, encode, keys
from shared.line_status import StatusCollector, to_json
from tests.support.factories import T0

DAY_NS = 86_400 * 1_000_000_000
HOUR_NS = 3_600 * 1_000_000_000


def told(tool_id: int, in_days: float, made_ns: int = T0) -> WearForecast:
    due_ns = made_ns + int(in_days * DAY_NS)
    return WearForecast(
        station="st1",
        tool_id=tool_id,
        time_ns=made_ns,
        horizon_days=7.0,
        due_ns=due_ns,
        early_ns=due_ns - 6 * HOUR_NS,
        late_ns=due_ns + 6 * HOUR_NS,
        production_days=in_days,
        runs_left=300,
        intensity_since_service=9e8,
        threshold=1e9,
        intensity_per_day=1e8,
        runs_since_service=4000,
        last_service_ns=None,
        service_by_ns=due_ns - 8 * HOUR_NS,
    )


def stats(forecasts: list[WearForecast], time_ns: int = T0) -> RecorderStats:
    return RecorderStats(
        station="st1",
        time_ns=time_ns,
        messages=10,
        lag_p50_ms=None,
        lag_max_ms=None,
        write_errors=0,
        last_error=None,
        recording=True,
        wear_forecasts=forecasts,
    )


def feed(collector: StatusCollector, topic: str, message: Any) -> None:
    collector.message(keys.station_key("st1", topic), encode(message), T0)


def test_a_forecast_heard_is_shown_the_soonest_first_and_the_recorder_says_what_is_current() -> (
    None
):
    collector = StatusCollector()
    feed(collector, channels.WEAR_FORECAST.topic, told(7, 3.0))
    feed(collector, channels.WEAR_FORECAST.topic, told(8, 1.5))
    (status,) = collector.report("tcp/x", 2.0, T0).stations
    assert [soon.tool_id for soon in status.wear_forecasts] == [8, 7]
    text = format_report(collector.report("tcp/x", 2.0, T0))
    (line,) = [line for line in text.splitlines() if "wear forecast" in line]
    assert "tool 8 due" in line and "1.5 production days" in line and "(+1 more)" in line
    assert "300 runs left" in line and "plan its service by" in line

    # the recorder's stats are what holds now: tool 8 was serviced, tool 9 came in
    feed(collector, channels.RECORDER.topic, stats([told(9, 5.0), told(7, 2.0)]))
    (status,) = collector.report("tcp/x", 2.0, T0).stations
    assert [(soon.tool_id, soon.in_days) for soon in status.wear_forecasts] == [(7, 2.0), (9, 5.0)]
    as_json = json.loads(json.dumps(to_json(collector.report("tcp/x", 2.0, T0))))
    assert as_json["stations"]["st1"]["wear_forecasts"][0]["tool_id"] == 7


def test_none_forecast_says_so() -> None:
    collector = StatusCollector()
    feed(collector, channels.RECORDER.topic, stats([]))
    text = format_report(collector.report("tcp/x", 2.0, T0))
    assert "no tool forecast due within the recorder's horizon" in text
