"""A bridge in a thread of the test's process, on real zenoh, and what it published.

The bridge is the service's own (:class:`OpenProtocolBridge` with the
station's queued publisher on a real zenoh peer session and the predictor's
real replay); a test hears what it published with
:class:`~tests.support.listener.Listener` (batches as samples) on another session.
"""

from __future__ import annotations

import threading
import tomllib
from pathlib import Path
from typing import Any

import zenoh

from services.openprotocol.bridge import OpenProtocolBridge
from services.openprotocol.bridge_counts import BridgeCounts
from services.openprotocol.controller_tightening import Curve, ResultFigures
from services.openprotocol.published_ids import position_path
from shared.config import load_any_station, toml_writer
from shared.runtime import QueuedPublisher
from tests.support.live_recorder import write_station_file


def bridge_station_file(folder: Path, port: int, endpoint: str, **section: Any) -> Path:
    """The shipped station file as a zenoh peer of ``endpoint`` with an ``[openprotocol]``
    section for the controller on 127.0.0.1:``port`` (short timers: tests stay fast)."""
    path = write_station_file(folder / "station.toml", folder / "recordings", connect=[endpoint])
    data = tomllib.loads(path.read_text())
    data["openprotocol"] = {
        "host": "127.0.0.1",
        "port": port,
        "keep_alive_s": 0.5,
        "reconnect_min_s": 0.05,
        "reconnect_max_s": 0.2,
        **section,
    }
    path.write_text(toml_writer.dumps(data))
    return path


CONTROLLER_STATION = Path(__file__).parents[2] / "config" / "controller-station.toml"


def controller_station_file(
    folder: Path, port: int, endpoint: str, programs: list[dict[str, Any]]
) -> Path:
    """The shipped controller station file (no [can]) as a zenoh peer of ``endpoint``,
    its controller on 127.0.0.1:``port`` (short timers), with ``programs`` as its psets."""
    data = tomllib.loads(CONTROLLER_STATION.read_text(encoding="utf-8"))
    data["zenoh"] = {"mode": "peer", "connect": [endpoint]}
    data["recorder"]["folder"] = str(folder / "recordings")
    data["openprotocol"] = {
        "host": "127.0.0.1",
        "port": port,
        "keep_alive_s": 0.5,
        "reconnect_min_s": 0.05,
        "reconnect_max_s": 0.2,
    }
    data["programs"] = programs
    path = folder / "controller-station.toml"
    path.write_text(toml_writer.dumps(data))
    return path


class RunningBridge:
    """The bridge of a station file, working in a thread until :meth:`finish`."""

    def __init__(self, station_file: Path, session: zenoh.Session, trace_timeout_s: float = 1.0):
        station = load_any_station(station_file)
        section = station.config.openprotocol
        assert section is not None
        self.counts = BridgeCounts(station.station_id, f"{section.host}:{section.port}")
        self.publisher = QueuedPublisher(session, station.station_id, batch_samples=True)
        self.position_file = position_path(station.recordings_folder, station.station_id)
        self.bridge = OpenProtocolBridge(
            station,
            section,
            self.publisher.publish,
            self.publisher.call,
            self.position_file,
            trace_timeout_s,
            self.counts,
        )
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self.bridge.work, args=(self.stop,))
        self.thread.start()

    def finish(self) -> None:
        self.stop.set()
        self.thread.join(timeout=10.0)
        self.publisher.close()


def key(tightening_id: int, time: str = "2026-11-24:10:00:00") -> str:
    return f"{time}|1|200.00|50|1|VIN{tightening_id}"


def figures(
    tightening_id: int, filled: bool = False, time: str = "2026-11-24:10:00:00"
) -> ResultFigures:
    return ResultFigures(
        tightening_id=tightening_id,
        program_id=1,
        time_ns=1_700_000_000_000_000_000,
        ok=True,
        torque_nm=200.0,
        torque_min_nm=180.0,
        torque_max_nm=240.0,
        torque_target_nm=200.0,
        angle_deg=50.0,
        angle_min_deg=35.0,
        angle_max_deg=65.0,
        angle_target_deg=None,
        part_id="VIN1",
        batch_size=10,
        batch_counter=3,
        strategy="",
        revision=2,
        filled=filled,
        key=key(tightening_id, time),
    )


def curve(tightening_id: int, kind: str) -> Curve:
    return Curve(tightening_id, kind, 1_700_000_000_000_000_000, 0.001, (1.0, 2.0, 3.0))
