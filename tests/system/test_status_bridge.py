"""``boltwatch status`` of a station with a controller bridge, as a real process against a
real router: a fake bridge (a zenoh client session of the test) keeps publishing
BridgeStats; status shows the link, the faults that are not zero, the last tightening id
and the alarm active on the controller, and the station's own services (the bridge, its
controller link, the recorder), not a CAN station's acquisition, predictor and rig; a CAN
station beside it is shown as ever. As a real bridge does, the fake one publishes an
alarm message only when the alarm is raised (long before status listens): the active
alarm comes with the bridge's stats, whatever status heard in its window."""

from __future__ import annotations

import json
import threading
import time
from dataclasses import replace
from pathlib import Path

import pytest

from shared.contract import BridgeStats, ControllerAlarm, channels, encode, keys
from shared.runtime import open_from, zenoh_config
from tests.support.fuzz.payloads import template
from tests.support.router_process import boltwatch
from tests.support.station_files import write_station

pytestmark = pytest.mark.system

STATION = "op-st4"
CAN_STATION = "can-st5"
S_NS = 1_000_000_000


def bridge_stats(now_ns: int) -> BridgeStats:
    stats: BridgeStats = template("openprotocol", STATION, now_ns, run_id=4711)
    return replace(
        stats,
        connected=False,
        connects=3,
        link_drops=2,
        results_filled=1,
        garbage_bytes=17,
        refused_values=1,
        epochs=1,
        last_error="link dropped: no data for 15 s",
        trace_reading="little-endian, scaling as declared",
        active_alarm=ControllerAlarm(
            STATION, now_ns - 5 * S_NS, now_ns, "E404", "raised", True, False, True, "overheated"
        ),
    )


def test_status_shows_the_bridge_link_its_faults_and_the_newest_active_alarm(
    router: str,
    tmp_path: Path,
) -> None:
    station_file = write_station(tmp_path, zenoh_port=int(router.rsplit(":", 1)[1]))
    session = open_from(zenoh_config("client", [router], connect_timeout_ms=5000))
    tokens = [
        session.liveliness().declare_token(keys.health_key(station, service))
        for station, service in ((STATION, "openprotocol"), (CAN_STATION, "acquisition"))
    ]
    stop = threading.Event()

    def publish() -> None:
        while not stop.is_set():
            now = time.time_ns()
            session.put(channels.OPENPROTOCOL.key(STATION), encode(bridge_stats(now)))
            time.sleep(0.1)

    thread = threading.Thread(target=publish, name="fake-bridge")
    thread.start()
    try:
        text = boltwatch("status", "--config", str(station_file), "--listen-s", "1.2")
        as_json = boltwatch("status", "--config", str(station_file), "--listen-s", "1.2", "--json")
    finally:
        stop.set()
        thread.join(10)
        for token in tokens:
            token.undeclare()
        session.close()

    assert text.returncode == 0, text.stderr
    block = text.stdout.split(f"station {STATION}\n", 1)[1]
    lines = {line[:16].strip(): line[16:] for line in block.splitlines()}
    assert lines["services"] == "openprotocol up, controller link DOWN, recorder DOWN"
    assert "bus" not in lines and "predictor" not in lines  # it runs neither
    can_block = text.stdout.split(f"station {CAN_STATION}\n", 1)[1].split("\n\n", 1)[0]
    can_lines = {line[:16].strip(): line[16:] for line in can_block.splitlines()}
    assert can_lines["services"] == "acquisition up, predictor DOWN, recorder DOWN, rig DOWN"
    assert can_lines["bus"].startswith("- (no BusStats in the window: acquisition down?)")
    assert can_lines["predictor"].startswith("- (no predictor stats in the window")
    assert lines["controller"].startswith(
        "NOT CONNECTED to 192.0.2.10:4545, MID 0061 revision 2, 4711 results, last tightening "
        "4711 (3 connects, "
    )
    assert lines["controller"].endswith(
        "; curves read little-endian, scaling as declared; last error: link dropped: no data "
        "for 15 s"
    )
    assert lines["bridge faults"] == (
        "2 link drops, 1 results filled after a reconnect, 17 garbage bytes, 1 refused values, "
        "1 new controller epochs"
    )
    assert lines["alarm"].startswith("E404 raised, 5.")
    assert lines["alarm"].endswith(": overheated (controller NOT ready, tool ready)")

    assert as_json.returncode == 0, as_json.stderr
    stations = json.loads(as_json.stdout)["stations"]
    assert stations[STATION]["services"] == {
        "openprotocol": True,
        "controller": False,
        "recorder": False,
    }
    assert (stations[STATION]["kind"], stations[CAN_STATION]["kind"]) == ("bridge", "can")
    assert list(stations[CAN_STATION]["services"]) == [
        "acquisition",
        "predictor",
        "recorder",
        "rig",
    ]
    bridge = stations[STATION]["bridge"]
    assert (bridge["controller"], bridge["connected"], bridge["last_tightening_id"]) == (
        "192.0.2.10:4545",
        False,
        4711,
    )
    assert bridge["faults"] == {
        "link_drops": 2,
        "results_filled": 1,
        "garbage_bytes": 17,
        "refused_values": 1,
        "epochs": 1,
    }
    assert bridge["alarm"]["error_code"] == "E404"
