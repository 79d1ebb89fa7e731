"""boltwatch status of a bridge station, the pure part: a station whose controller bridge
holds ``health/openprotocol`` or sends BridgeStats lists its own services (the bridge, its
controller link, the recorder), never a CAN station's acquisition, predictor and rig as
DOWN; a CAN station reads as before. Over a real router: tests/system/test_status_bridge.py.
"""

from __future__ import annotations

import json
from dataclasses import replace

from services.cli.station_status_text import format_report
from shared.contract import BridgeStats, channels, encode, keys
from shared.line_status import StatusCollector, to_json
from tests.support.fuzz.payloads import template

S = 1_000_000_000
T0 = 1_700_000_000 * S


def stats(connected: bool) -> BridgeStats:
    made: BridgeStats = template("openprotocol", "op1", T0, run_id=12)
    return replace(made, connected=connected)


def block(text: str, station: str) -> dict[str, str]:
    """label -> text of one station's block of the report."""
    lines = text.split(f"station {station}\n", 1)[1].split("\n\n", 1)[0].splitlines()
    return {line[:16].strip(): line[16:] for line in lines}


def test_a_bridge_station_lists_the_bridge_its_controller_link_and_the_recorder() -> None:
    collector = StatusCollector()
    for station, service in (("op1", "openprotocol"), ("op1", "recorder"), ("st1", "rig")):
        collector.alive(keys.health_key(station, service))
    collector.message(keys.station_key("op1", channels.OPENPROTOCOL.topic), encode(stats(True)), T0)

    report = collector.report("tcp/127.0.0.1:7447", 2.0, T0)

    op1, st1 = report.stations
    assert op1.services == {"openprotocol": True, "controller": True, "recorder": True}
    assert op1.kind == "bridge"
    assert st1.services == {
        "acquisition": False,
        "predictor": False,
        "recorder": False,
        "rig": True,
    }
    assert st1.kind == "can"
    text = format_report(report)
    bridge = block(text, "op1")
    assert bridge["services"] == "openprotocol up, controller link up, recorder up"
    assert "bus" not in bridge and "predictor" not in bridge
    assert bridge["controller"].startswith("connected to 192.0.2.10:4545")
    can = block(text, "st1")
    assert can["services"] == "acquisition DOWN, predictor DOWN, recorder DOWN, rig up"
    assert can["bus"].startswith("- (no BusStats in the window: acquisition down?)")
    data = json.loads(json.dumps(to_json(report)))["stations"]["op1"]
    assert data["kind"] == "bridge"
    assert data["services"] == {"openprotocol": True, "controller": True, "recorder": True}
    assert data["bridge"]["connected"] is True


def test_a_bridge_that_stopped_after_its_last_stats_is_down_and_its_link_too() -> None:
    """BridgeStats in the window, no token: the bridge went away (its last word counts)."""
    collector = StatusCollector()
    collector.message(
        keys.station_key("op1", channels.OPENPROTOCOL.topic), encode(stats(False)), T0
    )
    (op1,) = collector.report("e", 2.0, T0).stations
    assert op1.services == {"openprotocol": False, "controller": False, "recorder": False}


def test_a_token_alone_makes_a_bridge_station_and_stats_it_sends_still_show() -> None:
    """A bridge station whose acquisition stats did come (an odd line) shows them."""
    collector = StatusCollector()
    collector.alive(keys.health_key("op1", "openprotocol"))
    collector.message(
        keys.station_key("op1", channels.BUS.topic), encode(template("bus", "op1", T0)), T0
    )
    (op1,) = collector.report("e", 2.0, T0).stations
    assert op1.services == {"openprotocol": True, "controller": False, "recorder": False}
    lines = block(format_report(collector.report("e", 2.0, T0)), "op1")
    assert lines["bus"].startswith("0 gaps")
    assert "predictor" not in lines
