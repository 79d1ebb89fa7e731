"""``boltwatch serve rig`` end to end on a station file with a ``virtual`` CAN bus."""

from __future__ import annotations

import argparse
import threading
import uuid
from pathlib import Path

import can

from services.rig import service
from shared.contract import StationDatabase, ToolRunState
from tests.support.rig_fixtures import STATION_FILE


def virtual_station(tmp_path: Path, channel: str) -> Path:
    """The embedded station on a virtual bus, with a short program 1 (10 kN -> 12 kN)."""
    text = STATION_FILE.read_text()
    config_dir = STATION_FILE.parent
    text = text.replace('interface = "udp_multicast"', 'interface = "virtual"')
    text = text.replace('channel = "239.74.163.2"', f'channel = "{channel}"')
    text = text.replace("port = 43113\n", "")
    text = text.replace('"joints/', f'"{config_dir}/joints/')
    text = text.replace('"can/station.dbc"', f'"{config_dir}/can/station.dbc"')
    text = text.replace("target_force_n = 56000.0", "target_force_n = 12000.0")
    path = tmp_path / "station.toml"
    path.write_text(text)
    return path


def test_serve_rig_runs_n_runs_and_exits_zero(tmp_path: Path) -> None:
    channel = f"rig-{uuid.uuid4()}"
    station = virtual_station(tmp_path, channel)
    db = StationDatabase(STATION_FILE.parent / "can" / "station.dbc")
    args = argparse.Namespace(config=station, runs=2, program=1, first_run_id=500, seed=1)
    statuses: list[tuple[int, int]] = []
    with can.Bus(interface="virtual", channel=channel) as listener:
        done = threading.Event()

        def listen() -> None:
            while True:
                message = listener.recv(timeout=0.1)
                if message is None and done.is_set():
                    return  # the queue is drained
                if message is not None and message.arbitration_id == db.tool_status_id:
                    signals = db.decode(message.arbitration_id, message.data)
                    statuses.append((int(signals["RunId"]), int(signals["State"])))

        thread = threading.Thread(target=listen)
        thread.start()
        try:
            assert service.main(args) == 0
        finally:
            done.set()
            thread.join()
    finished = [(run_id, state) for run_id, state in statuses if state == ToolRunState.DONE]
    assert finished == [(500, ToolRunState.DONE), (501, ToolRunState.DONE)]
    assert statuses[-1] == (501, ToolRunState.IDLE)
