"""The page's "tools due soonest": every tool of the line once, forecast, the soonest first."""

from __future__ import annotations

import json
import time
from dataclasses import replace
from pathlib import Path

import pytest

from services.dashboard.line_board import LineBoard, StationSetting
from services.recorder.wear_queryable import reply_body
from shared.wear import CONTRACT_LIMITS, WearLedger
from tests.support import factories
from tests.support.wear_plant import TWO_SHIFTS, Plant, ledger_forecasts, plant_until, write_ledger

STATIONS = ("st1", "st2", "st3")
MOVED_RUN = 20_000_000


@pytest.fixture(scope="module")
def line(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Plant, int]:
    """Six weeks of three stations; tool 100 (st1's) ran once at st2 an hour ago."""
    now_ns = time.time_ns()
    plant = plant_until(replace(TWO_SHIFTS, days=42, stations=3), 12, now_ns)
    path = tmp_path_factory.mktemp("recordings") / "wear.sqlite"
    write_ledger(plant, path)
    ended_ns = now_ns - 3_600_000_000_000
    moved = factories.summary(
        MOVED_RUN,
        station="st2",
        tool_id=100,
        process_intensity=1e3,
        events=4,
        started_ns=ended_ns - 3_000_000_000,
        ended_ns=ended_ns,
    )
    with WearLedger(path) as ledger:
        ledger.add_run(moved, ended_ns, CONTRACT_LIMITS)
    return path, plant, now_ns


def test_each_tool_once_the_soonest_first_with_its_chart(line: tuple[Path, Plant, int]) -> None:
    path, plant, now_ns = line
    board = LineBoard([StationSetting(name, plant.threshold) for name in STATIONS], now_ns)
    for name in STATIONS:
        board.wear_reply(name, reply_body(path, "host", name), now_ns)
    shown = board.snapshot(now_ns)["tools_due"]
    assert [tool["stations"] for tool in shown if tool["tool_id"] == 100] == [["st1", "st2"]]
    tools, ranked = ledger_forecasts(path, plant.threshold, now_ns)
    expected = {told.tool_id: told for told in ranked}
    assert [tool["tool_id"] for tool in shown] == [told.tool_id for told in ranked]
    for tool in shown:
        told = expected[tool["tool_id"]]
        assert tool["forecast"]["state"] == told.state
        assert tool["forecast"]["due_ns"] == told.due_ns
        chart = tool["chart"]
        assert chart["threshold"] == plant.threshold
        # up to now (the reply's reading of the ledger): the intensity since service now
        assert chart["points"][-1][0] >= now_ns
        since = tools[tool["tool_id"]].intensity_since_service
        assert chart["points"][-1][1] == pytest.approx(since, rel=1e-12)
        if told.state == "forecast":
            assert chart["forecast"][1] == [told.due_ns, plant.threshold]
            assert chart["forecast"][0] == chart["points"][-1]
        assert tool["wears_it_most"] is not None
    json.dumps(shown)  # what /board.json and /events send


def test_a_reply_of_a_recorder_before_the_forecast_lists_its_tools_with_no_date(
    line: tuple[Path, Plant, int],
) -> None:
    path, plant, now_ns = line
    board = LineBoard([StationSetting("st1", plant.threshold)], now_ns)
    body = json.loads(reply_body(path, "host", "st1"))
    del body["outlooks"]
    board.wear_reply("st1", json.dumps(body).encode(), now_ns)
    (tool,) = board.snapshot(now_ns)["tools_due"]
    assert tool["tool_id"] == 100
    assert (tool["forecast"]["state"], tool["forecast"]["reason"]) == ("none", "no pace known")
    assert tool["chart"]["points"] == []
