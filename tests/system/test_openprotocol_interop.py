"""The bridge as a plant runs it, against a controller we did not write from our codec.

Router, recorder and bridge run as real processes (``boltwatch serve ...``),
the bridge with its default settings; the controller is
:class:`~tests.support.openprotocol_controller.SpecController`, written from
the specification's text and public implementations. What counts is what the
plant keeps: the MCAP recordings read back and the wear ledger.
"""

from __future__ import annotations

import contextlib
import os
import signal
import time
from collections import defaultdict
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from services.cli.station_supervisor import StationSupervisor
from tests.support.openprotocol_controller import SpecController
from tests.support.router_process import boltwatch
from tests.support.station_files import write_station
from tests.support.station_up import read_recordings, wear_ledger_rows

pytestmark = pytest.mark.system

STATION = "st1"
TIGHTENINGS = 10
WAIT_S = 60.0
#: short timers, so that a reconnect is a second, not half a minute
TIMERS = "keep_alive_s = 1.0\nreconnect_min_s = 0.2\nreconnect_max_s = 1.0\n"


class PlantStation:
    """Router, recorder and bridge processes of one station whose controller is ``controller``."""

    def __init__(self, folder: Path, controller: SpecController) -> None:
        self.folder = folder
        template = write_station(folder).read_text()
        self.station_file = folder / "bridge.toml"
        self.station_file.write_text(
            f'{template}\n[openprotocol]\nhost = "127.0.0.1"\nport = {controller.port}\n{TIMERS}'
        )
        self.supervisor = StationSupervisor(self.station_file, folder / "logs")
        zenoh_port = int(template.split("tcp/127.0.0.1:", 1)[1].split('"', 1)[0])
        self.supervisor.start("router", ["--listen", f"tcp/127.0.0.1:{zenoh_port}"])
        self.supervisor.start("recorder", ["--no-rerun"])
        self.bridges = 0
        self.start_bridge()

    def start_bridge(self) -> Any:
        self.bridges += 1
        name = "openprotocol" if self.bridges == 1 else f"openprotocol-{self.bridges}"
        self.bridge = self.supervisor.start("openprotocol", name=name)
        return self.bridge

    def logs(self) -> str:
        return "\n".join(
            f"--- {m.name}\n{m.log_path.read_text(errors='replace')}"
            for m in self.supervisor.processes
        )

    def stop(self) -> None:
        names = [m.name for m in self.supervisor.processes]
        order = [
            n for s in ("openprotocol", "recorder", "router") for n in names if n.startswith(s)
        ]
        self.supervisor.stop_all(order)

    def recorded(self) -> dict[str, list[dict[str, Any]]]:
        return read_recordings(self.folder / "recordings")

    def wear_runs(self) -> int:
        """The runs the wear ledger counted for the station's tool."""
        wear = boltwatch("wear", "--config", str(self.station_file), timeout_s=60, check=True)
        rows = wear_ledger_rows(wear.stdout, 7)
        assert len(rows) == 1, wear.stdout
        return int(rows[0][2])


@contextlib.contextmanager
def plant_station(folder: Path, controller: SpecController) -> Iterator[PlantStation]:
    station = PlantStation(folder, controller)
    try:
        yield station
    finally:
        station.stop()


def wait(condition: Any, what: str, station: PlantStation) -> None:
    deadline = time.monotonic() + WAIT_S
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"gave up waiting for {what}:\n{station.logs()}")
        time.sleep(0.1)


def tighten(controller: SpecController, count: int, part: str, **kwargs: Any) -> list[int]:
    return [
        controller.tighten(
            torque_nm=24.0 + 0.25 * i, angle_deg=150.0 + 7.0 * i, vin=f"{part}{i:04d}", **kwargs
        )
        for i in range(count)
    ]


def check_recorded_once(
    station: PlantStation, controller: SpecController, runs: int
) -> dict[str, list[dict[str, Any]]]:
    """Every run once in MCAP and in the wear ledger, with the controller's values."""
    logs = station.logs()
    assert "Traceback" not in logs, logs
    recorded = station.recorded()
    run_ids = sorted(summary["run_id"] for summary in recorded[f"boltwatch/{STATION}/runs"])
    assert run_ids == list(range(1, runs + 1)), logs
    results = recorded[f"boltwatch/{STATION}/results"]
    assert sorted(result["run_id"] for result in results) == run_ids
    for result in results:
        assert result["final_torque_nm"]["value"] is not None, result
        assert result["final_angle_deg"]["value"] is not None, result
    assert station.wear_runs() == runs
    return recorded


def peaks_by_run(recorded: dict[str, list[dict[str, Any]]]) -> dict[int, float]:
    peaks: dict[int, float] = defaultdict(lambda: -1e9)
    for sample in recorded[f"boltwatch/{STATION}/samples"]:
        peaks[sample["run_id"]] = max(peaks[sample["run_id"]], sample["torque_nm"])
    return dict(peaks)


def test_ten_tightenings_are_recorded_once_with_the_bridges_defaults(tmp_path: Path) -> None:
    """Before: 0 of 10 recorded (a 0005 naming 0900 was never taken for the answer to 0008)."""
    with SpecController(write_mode="coalesced") as controller:
        with plant_station(tmp_path, controller) as station:
            assert controller.wait_subscribed(WAIT_S, mids=(61, 900, 71))
            time.sleep(1.0)  # the recorder subscribed
            tighten(controller, TIGHTENINGS, "VIN")
            wait(lambda: len(controller.delivered_ids) >= TIGHTENINGS, "every 0062", station)
            time.sleep(3.0)  # the recorder's flush
        recorded = check_recorded_once(station, controller, TIGHTENINGS)
        peaks = peaks_by_run(recorded)
        for run_id in range(1, TIGHTENINGS + 1):
            assert peaks[run_id] == pytest.approx(controller.results[run_id].torque_nm, abs=0.011)


def test_a_bridge_killed_mid_batch_fills_the_gap_by_id_with_values(tmp_path: Path) -> None:
    with SpecController() as controller:
        with plant_station(tmp_path, controller) as station:
            assert controller.wait_subscribed(WAIT_S, mids=(61, 900))
            time.sleep(1.0)
            tighten(controller, 4, "VIN")
            wait(lambda: len(controller.delivered_ids) >= 4, "the first four", station)
            os.kill(station.bridge.pid, signal.SIGKILL)
            station.bridge.process.wait(10)
            tighten(controller, TIGHTENINGS - 4, "VJN")  # nobody listens
            station.start_bridge()
            wait(lambda: len(controller.delivered_ids) >= TIGHTENINGS, "the gap fetched", station)
            time.sleep(3.0)
        check_recorded_once(station, controller, TIGHTENINGS)
        fetched = [request for request in controller.old_result_requests if request[0] > 0]
        assert fetched and {revision for _, revision in fetched} == {2}, fetched


def test_a_controller_restarted_with_ids_from_1_loses_nothing(tmp_path: Path) -> None:
    with SpecController() as controller:
        with plant_station(tmp_path, controller) as station:
            assert controller.wait_subscribed(WAIT_S, mids=(61, 900))
            time.sleep(1.0)
            tighten(controller, TIGHTENINGS, "VIN")
            wait(lambda: len(controller.delivered_ids) >= TIGHTENINGS, "the first ten", station)
            controller.restart(next_id=1)  # the link drops; its ids start again
            tighten(controller, 3, "NEW", push=False)
            assert controller.wait_subscribed(WAIT_S, mids=(61, 900))
            tighten(controller, 2, "NXT")
            wait(lambda: set(controller.delivered_ids) >= {1, 2, 3, 4, 5}, "the reset's", station)
            time.sleep(3.0)
        check_recorded_once(station, controller, TIGHTENINGS + 5)


def test_a_little_endian_controllers_curves_are_read_right(tmp_path: Path) -> None:
    """Before: read big-endian, a 25 Nm tightening peaked at 322 Nm, nothing was counted, and
    the wear ledger took 2800 times the right intensity."""
    with SpecController(trace_byte_order="little") as controller:
        with plant_station(tmp_path, controller) as station:
            assert controller.wait_subscribed(WAIT_S, mids=(61, 900))
            time.sleep(1.0)
            tighten(controller, 3, "VIN")
            wait(lambda: len(controller.delivered_ids) >= 3, "three", station)
            time.sleep(3.0)
        recorded = check_recorded_once(station, controller, 3)
        peaks = peaks_by_run(recorded)
        assert peaks == pytest.approx(
            {i: controller.results[i].torque_nm for i in (1, 2, 3)}, abs=0.011
        )
        assert "little-endian" in station.logs()
