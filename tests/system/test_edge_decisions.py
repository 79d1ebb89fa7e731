"""An edge station decides on its own CAN thread and takes no decision from the network.

With ``[predictor] placement = "edge"`` the station's predictor runs in its
acquisition; a ``StopDecision`` put on ``boltwatch/<st>/decision`` by anyone
else (a rogue node on a plain-tcp line, a stray line predictor) must not stop
the tool, while the station's own predictor still does
(docs/explanation/decisions/0001-edge-stop-decision.md, docs/reference/access-control.md).
"""

from __future__ import annotations

import time
from pathlib import Path

import pytest
import zenoh

from services.cli.station_supervisor import stop_process
from shared.config import load_station
from shared.contract import StationDatabase, StopDecision, ToolRunState, channels, encode, keys
from shared.runtime import zenoh_config
from tests.support.can_injector import CanInjector, Pacer, StopListener
from tests.support.station_files import free_tcp_port, serve, write_station

pytestmark = pytest.mark.system

RUN = 7001


def test_a_decision_from_the_network_never_stops_an_edge_station(tmp_path: Path) -> None:
    port = free_tcp_port()
    path = write_station(tmp_path, zenoh_port=port)  # the shipped placement: edge
    station = load_station(path)
    database = StationDatabase(station.dbc_path)
    endpoint = f"tcp/127.0.0.1:{port}"
    router = serve(["router", "--listen", endpoint], tmp_path / "router.log")
    acquisition = serve(["acquisition", "--config", str(path)], tmp_path / "acquisition.log")
    try:
        with (
            zenoh.open(zenoh_config("client", [endpoint])) as session,
            StopListener(station.config.can, database) as stops,
            CanInjector(station.config.can, database) as bus,
        ):
            token = keys.health_key("st1", "predictor")
            deadline = time.monotonic() + 30.0
            while not any(r.ok is not None for r in session.liveliness().get(token)):
                assert time.monotonic() < deadline, (tmp_path / "acquisition.log").read_text()
                time.sleep(0.1)
            decisions = session.declare_publisher(channels.DECISION.key("st1"))
            bus.tool_status(RUN, ToolRunState.RUNNING)
            pacer = Pacer()
            for counter in range(300):  # a run far below its target and limits: no decision
                bus.tool_sensors(counter, 20.0, 0.1 * counter)
                bus.joint_sensors(counter, 12_000.0)
                pacer.wait()
                if counter == 150:
                    now = time.time_ns()
                    forged = StopDecision(
                        "st1", RUN, now, 0.15, "plateau_closest", "forged", 20.0, None, None, now
                    )
                    decisions.put(encode(forged))
            time.sleep(0.5)
            assert stops.heard == [], "a decision from the network stopped an edge station"
            for counter in range(300, 305):  # now over the 320 Nm hard limit: its own stop
                bus.tool_sensors(counter, 400.0, 0.1 * counter)
                bus.joint_sensors(counter, 12_000.0)
                pacer.wait()
            heard = stops.wait_for(1, 10.0)
            decisions.undeclare()
        assert [(h.run_id, h.reason) for h in heard] == [(RUN, 5)]  # torque_limit
    finally:
        stop_process(acquisition, grace_s=10.0)
        stop_process(router, grace_s=10.0)
