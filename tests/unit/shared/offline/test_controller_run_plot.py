"""``boltwatch inspect`` of a controller's run draws the controller's own windows and target.

A real bridge (the service's :class:`OpenProtocolBridge`, the predictor's replay) reads a
real TCP controller whose pset tightens to 25 Nm in a 23 to 27 Nm window, and publishes on
real zenoh to a real recorder; the recorded MCAP is drawn. Its torque panel carries the
controller's window and target from the run's result, never the station file's program
target (the shipped station's program 1: 200 Nm) nor the paper's model bands of the M14
joint: for a controller station's file, and for a CAN station's file with [openprotocol]
(whose joint and program records are in the recording, and are not the controller's).
"""

from __future__ import annotations

import tomllib
from collections.abc import Iterator
from pathlib import Path

import pytest
import zenoh

from services.cli.main import main
from shared.config import load_any_station, toml_writer
from shared.offline.post_mortem import build_figure, read_run
from shared.runtime import zenoh_config
from tests.support.bridge_harness import RunningBridge, bridge_station_file
from tests.support.live_recorder import RunningRecorder, free_port, wait_until
from tests.support.tcp_controller import TcpController

CONTROLLER_STATION = """\
[station]
id = "st1"
tool_id = 7

[zenoh]
mode = "peer"
listen = ["{endpoint}"]

[openprotocol]
host = "127.0.0.1"
port = {port}
keep_alive_s = 0.5
reconnect_min_s = 0.05
reconnect_max_s = 0.2

[recorder]
folder = "recordings"

[[programs]]
id = 1
name = "M6 cover screw"
torque_min_nm = 20.0
torque_max_nm = 30.0
"""


@pytest.fixture
def controller() -> Iterator[TcpController]:
    served = TcpController(torque_target_nm=25.0, torque_window_nm=(23.0, 27.0))
    yield served
    served.close()


def controller_station_file(folder: Path, port: int, endpoint: str) -> Path:
    path = folder / "controller-station.toml"
    path.write_text(CONTROLLER_STATION.format(endpoint=endpoint, port=port))
    return path


def can_station_file(folder: Path, port: int, endpoint: str) -> Path:
    """The shipped CAN station with an [openprotocol] section, the recorder listening."""
    path = bridge_station_file(folder, port, endpoint)
    data = tomllib.loads(path.read_text())
    data["zenoh"] = {"mode": "peer", "listen": [endpoint]}
    path.write_text(toml_writer.dumps(data))
    return path


def record_one_tightening(station_file: Path, controller: TcpController, endpoint: str) -> Path:
    """One tightening through the bridge into the recorder; the MCAP file of the run."""
    station = load_any_station(station_file)
    recorder = RunningRecorder(station)
    try:
        with zenoh.open(zenoh_config("peer", connect=[endpoint])) as feeding:
            bridge = RunningBridge(station_file, feeding)
            try:
                wait_until(lambda: controller.traces_subscribed, "the subscriptions")
                controller.tighten()
                wear = recorder.service.wear
                assert wear is not None
                wait_until(lambda: wear.counted == 1, "the run recorded")
            finally:
                bridge.finish()
    finally:
        recorder.finish()
    (path,) = station.recordings_folder.glob("st1/*/st1_run1_*.mcap")
    return path


@pytest.mark.parametrize("station_kind", ["controller station", "CAN station with a bridge"])
def test_inspect_of_a_bridge_run_draws_the_controllers_window_and_target(
    tmp_path: Path,
    controller: TcpController,
    station_kind: str,
    capsys: pytest.CaptureFixture[str],
) -> None:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    write = controller_station_file if station_kind == "controller station" else can_station_file
    mcap = record_one_tightening(write(tmp_path, controller.port, endpoint), controller, endpoint)

    run = read_run(mcap)
    assert run.controller is not None
    assert run.controller.torque_window_nm == (23.0, 27.0)
    assert run.controller.torque_target_nm == 25.0
    assert run.model() is None
    if station_kind == "CAN station with a bridge":  # the station's program and joint are there
        assert run.metadata["program"]["target_torque_nm"] == "200.0"
        assert run.metadata["joint"]["name"].startswith("M14")
    else:
        assert run.metadata["program"]["name"] == "M6 cover screw"
        assert "joint" not in run.metadata

    figure = build_figure(run)
    torque_labels = figure.axes[0].get_legend_handles_labels()[1]
    assert "controller's torque window 23 to 27 Nm" in torque_labels
    assert "controller's target 25 Nm" in torque_labels
    assert not any(
        label.startswith(("program target", "T_max", "T_min")) for label in torque_labels
    )
    force_labels = figure.axes[1].get_legend_handles_labels()[1]
    assert not any(label.startswith(("program target", "F_min", "F_max")) for label in force_labels)
    for axis in figure.axes[2:8]:  # Figs. 13-15: no model band, no K band
        labels = axis.get_legend_handles_labels()[1]
        assert not any("eqs." in label or "50 % relief" in label for label in labels), labels
    caption = figure.get_suptitle()
    assert "A controller's run (its result: controller): drawn against its own torque window " in (
        caption
    )
    assert "23 to 27 Nm, angle window 0 to 90 deg, target 25 Nm" in caption
    assert "No analytical bounds (a controller's run" in caption
    assert "M14" not in caption

    png = tmp_path / "run.png"
    assert main(["inspect", str(mcap), "--out", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "400 samples" in capsys.readouterr().out
