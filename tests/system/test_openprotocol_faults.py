"""The bridge's faults as a plant has them: real processes, real TCP, a real proxy.

Router, recorder, the simulated controller (``serve rig --controller
openprotocol --runs N``) and the bridge (``serve openprotocol``) run as the
station runs them; the bridge's station file points at a proxy of the test
(:mod:`tests.support.openprotocol_proxy`) that forwards to the controller's port
and damages what the controller says: the link pulled while a curve (0900) is
half forwarded, garbage bytes and a wrong length, a 0061 with a field out of
range. Another test SIGKILLs the bridge mid-run and starts it again. In every
case, after the controller's N tightenings: each tightening id is recorded once
(run summaries and results read back from MCAP, the wear ledger's runs), no
process wrote a traceback, and the fault is counted in ``BridgeStats`` and
shown by ``boltwatch status``.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import signal
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from services.cli.station_supervisor import ManagedProcess, StationSupervisor
from services.rig.openprotocol.simulated_controller import LINGER_S
from shared.contract import BridgeStats, channels
from tests.support.listener import Listener
from tests.support.live_recorder import free_port
from tests.support.live_station import open_client, wait_supervised
from tests.support.openprotocol_proxy import Damage, OpenProtocolProxy
from tests.support.router_process import boltwatch
from tests.support.station_files import write_station
from tests.support.station_up import read_recordings, wear_ledger_rows

pytestmark = pytest.mark.system

STATION = "st1"
RUNS = 4
DONE_TIMEOUT_S = 60.0
#: the controller's arguments besides --runs: short runs, ids from 1, the first once subscribed
CONTROLLER_ARGS: tuple[str, ...] = ("--controller", "openprotocol", "--program", "2")
CONTROLLER_ARGS += ("--first-run-id", "1", "--wait-for-integrator")
#: short timers, so that each fault is over in a second or two
TIMERS = """
keep_alive_s = 1.0
reconnect_min_s = 0.2
reconnect_max_s = 1.0

[rig.openprotocol]
ack_timeout_s = 1.0
link_timeout_s = 3.0
"""
#: MID 0061 revision 2's parameters 10 (batch counter), 11 (tightening status: 0 NOK, 1 OK), 12
TIGHTENING_STATUS = re.compile(rb"10\d{4}11([01])12\d13")


class FaultStation:
    """The processes of one station with a controller, the bridge behind the test's proxy."""

    def __init__(self, folder: Path) -> None:
        template = write_station(folder).read_text()
        controller_port = free_port()
        self.proxy = OpenProtocolProxy(controller_port)
        self.files: dict[str, Path] = {}
        for name, port in (("controller", controller_port), ("bridge", self.proxy.port)):
            self.files[name] = folder / f"{name}.toml"
            self.files[name].write_text(
                f'{template}\n[openprotocol]\nhost = "127.0.0.1"\nport = {port}\n{TIMERS}'
            )
        self.supervisor = StationSupervisor(self.files["bridge"], folder / "logs")
        endpoint = f"tcp/127.0.0.1:{_zenoh_port(template)}"
        self.supervisor.start("router", ["--listen", endpoint])
        self.session = open_client(endpoint)
        self.heard = Listener(self.session, STATION, (channels.OPENPROTOCOL.topic,))
        self.supervisor.start("recorder", ["--no-rerun"])
        self.bridges = 0
        self.start_bridge()
        self.rig = self.supervisor.start(
            "rig",
            [*CONTROLLER_ARGS, "--runs", str(RUNS)],
            config_paths=[self.files["controller"]],
        )

    @property
    def stats(self) -> list[BridgeStats]:
        """The bridge's BridgeStats heard so far."""
        return self.heard.of(channels.OPENPROTOCOL.topic)

    def start_bridge(self) -> ManagedProcess:
        self.bridges += 1
        name = "openprotocol" if self.bridges == 1 else f"openprotocol-{self.bridges}"
        self.bridge = self.supervisor.start("openprotocol", name=name)
        return self.bridge

    def wait_for(self, condition: Callable[[], bool], what: str) -> None:
        """Until ``condition``; a process that ended by itself (exit 0) is no failure."""
        exits = (0, -signal.SIGKILL)
        wait_supervised(self.supervisor, condition, what, DONE_TIMEOUT_S, 0.05, exits, self.logs)

    def finish(self) -> BridgeStats:
        """Wait for the controller's N tightenings and the bridge to publish the last one;
        the bridge's counters as it published it (the controller, done, then closes the
        link: a counter sent after that has one link drop more, whenever it came)."""
        self.wait_for(lambda: self.rig.exit_code() == 0, "the controller's runs delivered")
        self.wait_for(
            lambda: any(s.last_tightening_id == RUNS for s in self.stats[-3:]),
            f"the bridge to publish tightening {RUNS}",
        )
        return next(s for s in self.stats if s.last_tightening_id == RUNS)

    def status(self) -> dict[str, Any]:
        """``boltwatch status``, as text and as JSON: the station's bridge and its text lines."""
        command = ["status", "--config", str(self.files["bridge"]), "--listen-s", "1.5"]
        text, as_json = (
            boltwatch(*command, *extra, check=True).stdout for extra in ([], ["--json"])
        )
        bridge = json.loads(as_json)["stations"][STATION]["bridge"]
        bridge["text"] = text
        return dict(bridge)

    def logs(self) -> str:
        return "\n".join(
            f"--- {m.name}\n{m.log_path.read_text(errors='replace')}"
            for m in self.supervisor.processes
        )

    def close(self) -> None:
        self.heard.close()
        self.session.close()
        names = [m.name for m in self.supervisor.processes]
        order = [
            n
            for s in ("rig", "openprotocol", "recorder", "router")
            for n in names
            if n.startswith(s)
        ]
        self.supervisor.stop_all(order)
        self.proxy.close()


@contextlib.contextmanager
def fault_station(folder: Path) -> Iterator[FaultStation]:
    station = FaultStation(folder)
    try:
        yield station
    finally:
        station.close()


def _zenoh_port(station_text: str) -> int:
    return int(station_text.split("tcp/127.0.0.1:", 1)[1].split('"', 1)[0])


def check_each_tightening_recorded_once(station: FaultStation, folder: Path) -> None:
    """After the processes stopped: MCAP and the wear ledger hold tightenings 1..N once each,
    and no process wrote a traceback."""
    logs = station.logs()
    assert "Traceback" not in logs, logs
    messages = read_recordings(folder / "recordings")
    summaries = sorted(s["run_id"] for s in messages["boltwatch/st1/runs"])
    assert summaries == list(range(1, RUNS + 1)), logs
    results = sorted(r["tightening_id"] for r in messages["boltwatch/st1/results"])
    assert results == list(range(1, RUNS + 1)), logs
    wear = boltwatch("wear", "--config", str(station.files["bridge"]), timeout_s=60, check=True)
    (line,) = wear_ledger_rows(wear.stdout, 7)
    assert line[1:3] == ["SIM-7", str(RUNS)], wear.stdout


def shown(bridge: dict[str, Any], fault: str, words: str) -> None:
    """``fault`` is counted in the JSON and its words are on the text's "bridge faults" line."""
    assert bridge["faults"].get(fault, 0) >= 1, bridge
    (line,) = [
        row for row in bridge["text"].splitlines() if row.lstrip().startswith("bridge faults")
    ]
    assert words in line, line


def test_a_link_pulled_mid_trace_loses_no_tightening(tmp_path: Path) -> None:
    with fault_station(tmp_path) as station:
        # 0900s: torque and angle of tightening 1, then the torque of tightening 2: cut halfway
        cut = station.proxy.damage(Damage(mid=900, nth=3, kind="cut"))
        stats = station.finish()
        assert cut.done.is_set()
        assert stats.link_drops == 1 and stats.connects == 2, stats
        assert stats.repeated_results == 0, stats
        bridge = station.status()
    check_each_tightening_recorded_once(station, tmp_path)
    shown(bridge, "link_drops", "link drops")  # and one more: the controller ended


def test_garbage_and_a_wrong_length_lose_no_tightening(tmp_path: Path) -> None:
    with fault_station(tmp_path) as station:
        garbage = station.proxy.damage(Damage(mid=61, nth=2, kind="garbage"))
        stats = station.finish()
        assert garbage.done.is_set()
        assert stats.garbage_bytes >= len(b"NOT OPEN PROTOCOL"), stats
        assert stats.bad_messages >= 1, stats
        bridge = station.status()
    check_each_tightening_recorded_once(station, tmp_path)
    shown(bridge, "garbage_bytes", "garbage bytes")
    shown(bridge, "bad_messages", "bad messages")


def _status_seven(message: bytes) -> bytes:
    found = TIGHTENING_STATUS.search(message)
    assert found is not None, message
    return message[: found.start(1)] + b"7" + message[found.end(1) :]


def test_a_last_result_with_a_field_out_of_range_is_fetched_again(tmp_path: Path) -> None:
    with fault_station(tmp_path) as station:
        refused = station.proxy.damage(
            Damage(mid=61, nth=RUNS, kind="rewrite", rewrite=_status_seven)
        )
        stats = station.finish()
        assert refused.done.is_set()
        assert stats.refused_values == 1 and stats.results_filled == 1, stats
        assert stats.link_drops == 0, stats
        bridge = station.status()
    check_each_tightening_recorded_once(station, tmp_path)
    shown(bridge, "refused_values", "1 refused values")


def test_a_bridge_killed_mid_run_and_started_again_loses_no_tightening(tmp_path: Path) -> None:
    with fault_station(tmp_path) as station:
        first = station.bridge
        station.wait_for(
            lambda: any(s.last_tightening_id == 1 for s in station.stats), "tightening 1 published"
        )
        os.kill(first.pid, signal.SIGKILL)
        first.process.wait(10)
        # the controller tightens on while no bridge listens; the bridge is slow to come back
        station.wait_for(
            lambda: f"tightening {RUNS}:" in station.rig.log_path.read_text(),
            f"the controller's tightening {RUNS}",
        )
        time.sleep(LINGER_S + 1.0)
        station.start_bridge()
        stats = station.finish()
        assert stats.started_ns > first_started(station), stats
        # the new process: tightenings 2 to N, fetched by id, each once
        assert stats.results == stats.results_filled == RUNS - 1, stats
        assert stats.repeated_results == 0, stats
        bridge = station.status()
    check_each_tightening_recorded_once(station, tmp_path)
    shown(bridge, "results_filled", "results filled after a reconnect")


def first_started(station: FaultStation) -> int:
    return min(s.started_ns for s in station.stats)
