"""Every line's wear replies with their tools' outlooks: read back, merged, forecast."""

from __future__ import annotations

import json
import time
from dataclasses import replace
from pathlib import Path

from services.recorder.wear_queryable import reply_body
from shared.wear import WearLedger, forecast, merge, parse_reply
from tests.support.wear_plant import TWO_SHIFTS, plant_until, write_ledger


def test_a_tool_of_one_ledger_keeps_its_outlook_and_one_of_two_has_none(tmp_path: Path) -> None:
    now_ns = time.time_ns()
    plant = plant_until(replace(TWO_SHIFTS, days=28, stations=2), 6, now_ns)
    for line in ("a", "b"):
        (tmp_path / line).mkdir()
        write_ledger(plant, tmp_path / line / "wear.sqlite")  # the same tools on two lines
    (tmp_path / "c").mkdir()
    write_ledger(replace(plant, tool_id=plant.tool_id + 100), tmp_path / "c" / "wear.sqlite")
    replies = [
        parse_reply(reply_body(tmp_path / line / "wear.sqlite", line, "st1"))
        for line in ("a", "b", "c")
    ]
    with WearLedger(tmp_path / "c" / "wear.sqlite", read_only=True) as ledger:
        alone = ledger.tool(200)
    (read,) = replies[2].tools
    assert read.outlook == alone.outlook  # JSON and back: the same pace, calendar, causes
    merged = {tool.tool_id: tool for tool in merge(replies)}
    assert merged[100].outlook is None  # measured in two ledgers: no pace for the plant
    assert merged[200].outlook == alone.outlook
    told = forecast(100, None, None, merged[100].intensity_since_service, 1e12, now_ns)
    assert (told.state, told.reason) == ("none", "no pace known")


def test_a_reply_of_a_recorder_before_the_forecast_is_read_as_it_was(tmp_path: Path) -> None:
    plant = plant_until(replace(TWO_SHIFTS, days=14, stations=2), 6, time.time_ns())
    write_ledger(plant, tmp_path / "wear.sqlite")
    body = json.loads(reply_body(tmp_path / "wear.sqlite", "host", "st1"))
    del body["outlooks"]
    (tool,) = parse_reply(json.dumps(body).encode()).tools
    assert (tool.tool_id, tool.outlook) == (100, None)
