"""The line's page, its pure part: what the board makes of what arrives."""

from __future__ import annotations

import json
from typing import Any

import pytest

from services.dashboard import line_board
from services.dashboard.line_board import HISTORY, LineBoard, StationSetting
from shared.config import StationPlace
from shared.contract import (
    QualityAlert,
    QualityFigure,
    TighteningResult,
    WearAlert,
    channels,
    encode,
    keys,
)
from shared.errors import InputError
from shared.quality import cycle_result
from tests.support.factories import T0, S, result, summary


def board() -> LineBoard:
    return LineBoard([StationSetting("st1", 1.0e6), StationSetting("st2", None)], T0)


def put(board: LineBoard, topic: str, message: object, station: str = "st1") -> bool:
    return board.message(keys.station_key(station, topic), encode(message), T0)


def station(board: LineBoard, name: str = "st1") -> dict[str, Any]:
    return next(s for s in board.snapshot(T0 + S)["stations"] if s["station"] == name)


def wear_reply(intensity: float) -> bytes:
    tool = {
        "tool_id": 7,
        "runs": 12,
        "runs_since_service": 5,
        "intensity_since_service": intensity,
        "total_intensity": 3 * intensity,
    }
    return json.dumps({"station": "st1", "ledger": "/x", "host": "h", "tools": [tool]}).encode()


def alert(tool_id: int, time_ns: int) -> WearAlert:
    return WearAlert("st1", tool_id, time_ns, 1.2e6, 1.0e6, 5, None)


def test_each_station_shows_where_it_is_as_its_station_file_says() -> None:
    placed = StationSetting("st1", None, StationPlace("North", "B", "Wheel nuts"))
    line = LineBoard([placed, StationSetting("st2", None)], T0)
    assert [(s["name"], s["plant"], s["line"]) for s in line.snapshot(T0)["stations"]] == [
        ("Wheel nuts", "North", "B"),
        ("", "", ""),
    ]


def test_services_alive_are_those_of_the_last_window_only() -> None:
    line = board()
    line.close_window([keys.health_key("st1", "recorder"), keys.health_key("st1", "extra")], T0)
    shown = station(line)["services"]
    assert shown == {
        "acquisition": False,
        "predictor": False,
        "recorder": True,
        "rig": False,
        "extra": True,
    }
    line.close_window([], T0 + 2 * S)  # the recorder's token is gone
    assert station(line)["services"] == dict.fromkeys(
        ["acquisition", "predictor", "recorder", "rig"], False
    )


def test_the_last_stop_reasons_newest_first_and_a_tool_that_stopped_itself() -> None:
    line = board()
    for run_id in range(HISTORY + 2):
        assert put(
            line,
            channels.RUNS.topic,
            summary(run_id, stop_reason=None if run_id == 11 else "plateau_closest"),
        )
    stops = station(line)["stops"]
    assert [stop["run_id"] for stop in stops] == list(range(HISTORY + 1, 1, -1))
    assert stops[0]["stop_reason"] == "tool (done)" and stops[1]["stop_reason"] == "plateau_closest"
    assert station(line, "st2")["stops"] == []


def test_wear_against_the_threshold_and_a_failed_reply_keeps_the_last_table() -> None:
    line = board()
    assert station(line)["wear_error"] == "no reply from the recorder yet"
    line.wear_reply("st1", wear_reply(0.5e6), T0)
    (tool,) = station(line)["wear"]
    assert tool["used"] == pytest.approx(0.5) and tool["due"] is False
    line.wear_reply("st1", wear_reply(1.0e6), T0)
    assert station(line)["wear"][0]["due"] is True
    with pytest.raises(InputError, match="not a wear reply"):
        line.wear_reply("st1", b'{"tools": [{"tool_id": 7}]}', T0)
    line.wear_failed("st1", "no recorder answered", T0)
    shown = station(line)
    assert shown["wear_error"] == "no recorder answered" and shown["wear"][0]["due"] is True
    line.wear_reply("st2", wear_reply(0.5e6), T0)  # no threshold: no fraction, never due
    assert station(line, "st2")["wear"][0]["used"] is None


def test_alerts_latest_per_tool_and_any_alert_channel_of_the_table(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    line = board()
    assert put(line, channels.WEAR_ALERT.topic, alert(7, T0 - 2 * S))
    assert put(line, channels.WEAR_ALERT.topic, alert(7, T0 - S))  # replaces tool 7's
    assert put(line, channels.WEAR_ALERT.topic, alert(8, T0 - 3 * S))
    alerts = station(line)["alerts"]
    assert [a["time_ns"] for a in alerts] == [T0 - S, T0 - 3 * S]
    assert alerts[0]["text"].startswith("tool 7 due for service: intensity since service 1.2e+06")
    # an alert channel another service adds is shown by its fields, with no change here
    other = channels.Channel("other/alert", WearAlert, "report")
    monkeypatch.setitem(line_board.ALERT_CHANNELS, other.topic, other)
    assert put(line, other.topic, alert(9, T0))
    newest = station(line)["alerts"][0]
    assert newest["topic"] == "other/alert"
    assert newest["text"].startswith("tool id 9, intensity since service 1.2e+06")


def test_messages_of_stations_not_served_and_unreadable_ones_are_left() -> None:
    line = board()
    assert not put(line, channels.RUNS.topic, summary(1), station="st9")
    assert not line.message(keys.station_key("st1", channels.RUNS.topic), b"{}", T0)
    assert station(line)["stops"] == [] and station(line)["unreadable_messages"] == 1
    assert not line.message("elsewhere/st1/runs", b"", T0)


def quality_alert(figure: QualityFigure, time_ns: int, active: bool = True) -> QualityAlert:
    words = "below" if active else "back to at least"
    text = f"program 1: {figure} Cpk 0.9 {words} 1.33 over the last 50 runs"
    return QualityAlert("st1", 1, time_ns, "cpk_low", figure, 0.9, 1.33, 50, active, text)


def test_quality_alerts_show_in_words_one_per_figure_the_latest_word_kept() -> None:
    line = board()
    assert put(line, channels.QUALITY_ALERT.topic, quality_alert("preload", T0 - 3 * S))
    assert put(line, channels.QUALITY_ALERT.topic, quality_alert("torque", T0 - 2 * S))
    assert put(line, channels.QUALITY_ALERT.topic, quality_alert("preload", T0 - S, False))
    alerts = station(line)["alerts"]
    assert [(a["topic"], a["text"]) for a in alerts] == [
        (
            "quality/alert",
            "cpk_low: program 1: preload Cpk 0.9 back to at least 1.33 over the last 50 runs "
            "(cleared)",
        ),
        ("quality/alert", "cpk_low: program 1: torque Cpk 0.9 below 1.33 over the last 50 runs"),
    ]


def spindle_result(cycle: int, spindle: int, nok: bool = False) -> TighteningResult:
    return result(
        5000 + cycle * 10 + spindle,
        spindle=spindle,
        sync_id=7000 + cycle,
        part_id=f"P{cycle}",
        time_ns=T0 + cycle * S + spindle,
        result="NOK" if nok else "OK",
        nok_reasons="torque low" if nok else "",
    )


def test_a_multi_spindle_station_s_results_say_their_spindle_cycle_and_common_result() -> None:
    line = board()
    came = {k: spindle_result(0, k, nok=k == 3) for k in range(1, 5)}
    for spindle_run in came.values():
        assert put(line, channels.RESULTS.topic, spindle_run)
    shown = station(line)["results"]
    assert [(r["run_id"], r["spindle"], r["sync_id"]) for r in shown] == [
        (5000 + k, k, 7000) for k in (4, 3, 2, 1)
    ]
    assert {r["cycle"] for r in shown} == {None}  # its common result has not come yet
    assert put(line, channels.CYCLES.topic, cycle_result("st1", 7000, 4, came))
    common = {
        "sync_id": 7000,
        "spindles": 4,
        "result": "NOK",
        "nok_reasons": "spindle 3 NOK (torque low)",
        "part_id": "P0",
    }
    assert [r["cycle"] for r in station(line)["results"]] == [common] * 4
    # the last HISTORY cycles of every spindle, not the last HISTORY spindles' runs
    for cycle in range(1, HISTORY + 2):
        for k in range(1, 5):
            put(line, channels.RESULTS.topic, spindle_result(cycle, k))
    shown = station(line)["results"]
    assert len(shown) == HISTORY * 4
    assert {r["sync_id"] for r in shown} == set(range(7002, 7002 + HISTORY))


def test_a_single_spindle_station_s_results_and_stops_say_no_spindle() -> None:
    line = board()
    assert put(line, channels.RESULTS.topic, result(1, part_id="P1"))
    assert put(line, channels.RUNS.topic, summary(1))
    (shown,) = station(line)["results"]
    (stop,) = station(line)["stops"]
    assert not {"spindle", "sync_id", "cycle"} & (set(shown) | set(stop))
