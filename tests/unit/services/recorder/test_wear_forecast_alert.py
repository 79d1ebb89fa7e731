"""The recorder forecasts a tool's service: a WearForecast once per horizon, in RecorderStats."""

from __future__ import annotations

import json
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import zenoh

from shared.config import LoadedStation, load_station
from shared.contract import channels, encode
from shared.wear import WearLedger
from tests.support import factories
from tests.support.live_recorder import (
    RunningRecorder,
    has_subscribers,
    wait_until,
    write_station_file,
)
from tests.support.wear_plant import TWO_SHIFTS, plant_until, write_ledger

S_NS = 1_000_000_000
DAY_NS = 86_400 * S_NS
TOOL = 100  # the simulated plant's tool at st1
#: the threshold is this many of the tool's production days ahead of its wear now
DAYS_AHEAD = 2.0


@pytest.fixture
def station(tmp_path: Path, endpoint: str) -> LoadedStation:
    """Six weeks of a two-shift plant in the ledger; the threshold two production days of
    tool 100's wear above its intensity since its service."""
    now_ns = time.time_ns()
    plant = plant_until(replace(TWO_SHIFTS, days=42, stations=2), 8, now_ns)
    recordings = tmp_path / "recordings"
    recordings.mkdir()
    write_ledger(plant, recordings / "wear.sqlite")
    with WearLedger(recordings / "wear.sqlite", read_only=True) as ledger:
        since = ledger.tool(TOOL, outlook=False).intensity_since_service
    recent = (plant.tool_id == TOOL) & (plant.ended_ns > now_ns - 14 * DAY_NS)
    days = len({plant.calendar.position(int(t)) // 1 for t in plant.ended_ns[recent]})
    per_day = float(np.sum(plant.intensity[recent])) / days
    path = write_station_file(
        tmp_path / "station.toml",
        recordings,
        listen=[endpoint],
        recorder={
            "wear_service_threshold": since + DAYS_AHEAD * per_day,
            "wear_forecast_days": [7.0, 0.5],
        },
    )
    return load_station(path)


def run_summary(run_id: int) -> bytes:
    ended_ns = time.time_ns()
    return encode(
        factories.summary(
            run_id,
            tool_id=TOOL,
            events=4,
            process_intensity=1000.0,
            samples=3000,
            started_ns=ended_ns - 3 * S_NS,
            ended_ns=ended_ns,
        )
    )


def test_a_tool_forecast_due_within_the_horizon_is_said_once_and_kept_in_recorder_stats(
    station: LoadedStation, recorder: RunningRecorder, publisher_session: zenoh.Session
) -> None:
    forecasts: list[dict[str, object]] = []
    stats: list[dict[str, object]] = []
    subscribers = [
        publisher_session.declare_subscriber(
            channels.WEAR_FORECAST.key("st1"),
            lambda sample: forecasts.append(json.loads(sample.payload.to_bytes())),
        ),
        publisher_session.declare_subscriber(
            channels.RECORDER.key("st1"),
            lambda sample: stats.append(json.loads(sample.payload.to_bytes())),
        ),
    ]
    runs = publisher_session.declare_publisher(channels.RUNS.key("st1"))
    wait_until(lambda: has_subscribers(runs), "the recorder")
    wear = recorder.service.wear
    assert wear is not None
    for run_id in (10_000_001, 10_000_002, 10_000_003):
        runs.put(run_summary(run_id))
    wait_until(lambda: wear.counted == 3, "the runs counted")
    counted_ns = time.time_ns()

    def stats_after_the_runs() -> bool:
        """RecorderStats made after the third run: every forecast put before it came first."""
        return any(
            message["time_ns"] > counted_ns  # type: ignore[operator]
            and [told["tool_id"] for told in message["wear_forecasts"]] == [TOOL]  # type: ignore[attr-defined]
            for message in stats
        )

    wait_until(stats_after_the_runs, "RecorderStats with the forecast")
    (said,) = forecasts  # once for the 7-day horizon, not after each run; not within 0.5 day
    assert (said["tool_id"], said["horizon_days"], said["station"]) == (TOOL, 7.0, "st1")
    threshold = station.config.recorder.wear_service_threshold
    assert said["threshold"] == threshold
    assert isinstance(said["due_ns"], int) and isinstance(said["early_ns"], int)
    assert counted_ns < said["early_ns"] <= said["due_ns"] < counted_ns + 7 * DAY_NS
    assert said["late_ns"] is None or said["due_ns"] <= said["late_ns"]  # type: ignore[operator]
    assert isinstance(said["production_days"], float)
    assert 1.0 < said["production_days"] < 3.5  # two production days of its pace
    assert isinstance(said["runs_left"], int) and said["runs_left"] > 0
    for subscriber in subscribers:
        subscriber.undeclare()
    runs.undeclare()
