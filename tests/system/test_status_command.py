"""``boltwatch status`` as a real process against a real router and a fake station.

The fake station is a zenoh client session in the test: it declares the
acquisition's and predictor's liveliness tokens and keeps publishing Samples,
BusStats, ToolState, a StopDecision and a RunSummary until ``status`` ends.
"""

from __future__ import annotations

import json
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from services.cli.station_supervisor import stop_process
from shared.contract import (
    BusStats,
    RunSummary,
    StopDecision,
    ToolState,
    channels,
    encode,
    keys,
)
from shared.runtime import open_from, zenoh_config
from tests.support import factories
from tests.support.paths import REPO
from tests.support.router_process import boltwatch
from tests.support.station_files import free_tcp_port, write_station

pytestmark = pytest.mark.system

STATION = "line3-st9"
PUBLISH_PERIOD_S = 0.005  # ~200 samples/s: enough to see, cheap to send


class FakeStation:
    """Publishes what an acquisition and a predictor would, from one client session."""

    def __init__(self, endpoint: str) -> None:
        self.session = open_from(zenoh_config("client", [endpoint], connect_timeout_ms=5000))
        liveliness = self.session.liveliness()
        self.tokens = [
            liveliness.declare_token(keys.health_key(STATION, service))
            for service in ("acquisition", "predictor")
        ]
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._publish, name="fake-station")

    def __enter__(self) -> FakeStation:
        self.thread.start()
        return self

    def __exit__(self, *_exc: object) -> None:
        self.stop.set()
        self.thread.join(10)
        for token in self.tokens:
            token.undeclare()
        self.session.close()

    def _put(self, topic: str, message: object) -> None:
        self.session.put(keys.station_key(STATION, topic), encode(message))

    def _publish(self) -> None:
        sequence = 0
        while not self.stop.is_set():
            now = time.time_ns()
            sample = factories.sample(12, sequence, station=STATION, time_ns=now)
            self._put(channels.SAMPLES.topic, sample)
            if sequence % 40 == 0:  # five times a second (the real ones: on change, 1 Hz)
                self._put(channels.TOOL.topic, ToolState(STATION, 12, 7, 1, "running", now))
                self._put(channels.BUS.topic, bus_stats(now, samples=sequence))
                self._put(channels.DECISION.topic, decision(now))
                self._put(channels.RUNS.topic, run_summary(now))
            sequence += 1
            time.sleep(PUBLISH_PERIOD_S)


def bus_stats(now_ns: int, samples: int) -> BusStats:
    return BusStats(
        station=STATION,
        time_ns=now_ns,
        frames=2 * samples + 5,
        samples=samples,
        unknown_ids=0,
        wrong_length=1,
        decode_errors=0,
        error_frames=2,
        receive_errors=0,
        counter_gaps=3,
        missed_samples=4,
        counter_faults=0,
        unpaired=0,
        orphans=0,
        stop_commands=11,
    )


def decision(now_ns: int) -> StopDecision:
    return StopDecision(
        STATION, 11, now_ns, 2.5, "plateau_closest", "next plateau farther", 190.0, 55.0e3,
        57.0e3, now_ns,
    )  # fmt: skip


def run_summary(now_ns: int) -> RunSummary:
    """Run 11, ended now: 55.9 kN of 56 kN."""
    return factories.summary(
        11,
        station=STATION,
        target_force_n=56000.0,
        reached_force_n=55900.0,
        reached_torque_nm=195.0,
        error_pct=-0.18,
        events=8,
        process_intensity=0.3,
        samples=2400,
        started_ns=now_ns - 3_000_000_000,
        ended_ns=now_ns,
    )


def test_status_json_shows_the_fake_station(router: str, tmp_path: Path) -> None:
    station_file = write_station(tmp_path, zenoh_port=int(router.rsplit(":", 1)[1]))
    with FakeStation(router):
        result = boltwatch("status", "--config", str(station_file), "--listen-s", "1.2", "--json")

    assert result.returncode == 0, result.stderr
    report = json.loads(result.stdout)
    assert report["endpoint"] == router
    status = report["stations"][STATION]
    assert status["services"] == {
        "acquisition": True,
        "predictor": True,
        "recorder": False,
        "rig": False,
    }
    assert status["samples_per_s"] > 0
    assert status["bus"]["counter_gaps"] == 3 and status["bus"]["missed_samples"] == 4
    assert status["bus"]["bad_frames"] == 3
    assert status["last_run"]["run_id"] == 12 and status["last_run"]["state"] == "running"
    assert status["last_decision"]["reason"] == "plateau_closest"
    assert status["last_decision"]["run_id"] == 11
    summary = status["last_summary"]
    assert (summary["run_id"], summary["target"], summary["reached"]) == (11, 56000.0, 55900.0)
    assert summary["error_pct"] == -0.18
    assert status["recorder"] is None  # no recorder serves it
    assert status["unreadable_messages"] == 0


@pytest.fixture
def recorder_process(router: str, tmp_path: Path) -> Iterator[subprocess.Popen[bytes]]:
    """A real ``boltwatch serve recorder`` for STATION, a client of ``router``, once it is up."""
    station_file = write_station(
        tmp_path,
        zenoh_port=int(router.rsplit(":", 1)[1]),
        replacements={'id = "st1"': f'id = "{STATION}"'},
    )
    log_path = tmp_path / "recorder.log"
    log = log_path.open("w")
    process = subprocess.Popen(
        [sys.executable, "-m", "services.cli", "serve", "recorder", "--config", str(station_file),
         "--no-rerun"],
        cwd=REPO, stdout=log, stderr=subprocess.STDOUT,
    )  # fmt: skip
    watcher = open_from(zenoh_config("client", [router], connect_timeout_ms=5000))
    try:
        deadline = time.monotonic() + 30
        token = keys.health_key(STATION, "recorder")
        while not any(r.ok is not None for r in watcher.liveliness().get(token, timeout=1)):
            assert process.poll() is None, log_path.read_text()
            assert time.monotonic() < deadline, "the recorder never came up"
            time.sleep(0.1)
        yield process
    finally:
        watcher.close()
        stop_process(process, grace_s=10)
        log.close()


def test_status_shows_the_recorder_lag_and_health(
    router: str, recorder_process: subprocess.Popen[bytes]
) -> None:
    with FakeStation(router):
        json_run = boltwatch("status", "--connect", router, "--listen-s", "2.5", "--json")
        text_run = boltwatch("status", "--connect", router, "--listen-s", "2.5")

    assert json_run.returncode == 0, json_run.stderr
    status = json.loads(json_run.stdout)["stations"][STATION]
    assert status["services"]["recorder"] is True
    recorder = status["recorder"]
    assert recorder is not None, status
    assert recorder["recording"] is True and recorder["write_errors"] == 0
    assert recorder["last_error"] is None
    assert recorder["messages"] > 0
    assert 0 <= recorder["lag_p50_ms"] <= recorder["lag_max_ms"]
    assert text_run.returncode == 0, text_run.stderr
    assert "recorder      recording, lag p50 " in text_run.stdout


def test_status_with_nothing_alive_connects_and_says_so(router: str) -> None:
    result = boltwatch("status", "--connect", router, "--listen-s", "0.3")

    assert result.returncode == 0, result.stderr
    assert f"connected to {router}" in result.stdout
    assert "no station seen" in result.stdout


def test_status_without_a_router_fails_with_one_line() -> None:
    endpoint = f"tcp/127.0.0.1:{free_tcp_port()}"  # nothing listens there

    result = boltwatch("status", "--connect", endpoint, "--listen-s", "0.3")

    assert result.returncode == 2
    assert result.stdout == ""
    (line,) = result.stderr.strip().splitlines()
    assert line.startswith(f"boltwatch status: cannot reach the zenoh router at {endpoint}")


def test_status_module_imports_no_zenoh() -> None:
    # 'boltwatch --help' imports every command module: heavy imports belong in run().
    check = "import sys, services.cli.commands.status; print('zenoh' in sys.modules)"
    result = subprocess.run(
        [sys.executable, "-c", check], capture_output=True, text=True, cwd=REPO, check=True
    )
    assert result.stdout.strip() == "False"
