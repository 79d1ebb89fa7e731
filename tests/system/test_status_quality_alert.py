"""``boltwatch status`` shows the recorder's quality alert: a real router, a
real recorder fed real TighteningResults (3 NOK in a row), and status as a real process."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import pytest
import zenoh

from shared.config import load_station
from shared.contract import JudgedFigure, TighteningResult, Verdict, channels, encode, keys
from shared.runtime import open_from, zenoh_config
from tests.support import factories
from tests.support.live_recorder import (
    RunningRecorder,
    has_subscribers,
    wait_until,
    write_station_file,
)
from tests.support.paths import REPO
from tests.support.router_process import boltwatch

pytestmark = pytest.mark.system

S_NS = 1_000_000_000


def result(run_id: int, verdict: Verdict) -> TighteningResult:
    """A result of program 2 that ended a second ago: its preload 52 kN, ``verdict``."""
    return factories.result(
        run_id,
        program_id=2,
        time_ns=time.time_ns() - S_NS,
        final_torque_nm=JudgedFigure(210.0, 180.0, 240.0, "ok"),
        final_angle_deg=JudgedFigure(47.0, 35.0, None, "ok"),
        final_force_n=JudgedFigure(52000.0, 53000.0, 59000.0, "ok" if verdict == "OK" else "low"),
        result=verdict,
        nok_reasons="" if verdict == "OK" else "preload low: 52000.0",
    )


def status_during_an_alert(
    session: zenoh.Session, station_file: Path, first_run: int, *extra: str
) -> subprocess.CompletedProcess[str]:
    """Start ``boltwatch status``; once it listens, put OK + 3 NOK (the alert starts)."""
    command = ["status", "--config", str(station_file), "--listen-s", "3", *extra]
    process = subprocess.Popen(
        [sys.executable, "-m", "services.cli", *command],
        cwd=REPO,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    # only status listens to every station: the recorder hears its own (st1) alone
    probe = session.declare_publisher(keys.station_key("probe", "quality/alert"))
    results = session.declare_publisher(channels.RESULTS.key("st1"))
    try:
        wait_until(lambda: has_subscribers(probe), "status to listen", timeout_s=30)
        wait_until(lambda: has_subscribers(results), "the recorder")
        verdicts: list[Verdict] = ["OK", "NOK", "NOK", "NOK"]
        for n, verdict in enumerate(verdicts):
            results.put(encode(result(first_run + n, verdict)))
        out, err = process.communicate(timeout=30)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
        probe.undeclare()
        results.undeclare()
    return subprocess.CompletedProcess(process.args, process.returncode, out, err)


def test_status_shows_the_newest_active_quality_alert(
    router: str,
    tmp_path: Path,
) -> None:
    station_file = write_station_file(
        tmp_path / "station.toml", tmp_path / "recordings", connect=[router]
    )
    recorder = RunningRecorder(load_station(station_file))
    session = open_from(zenoh_config("client", [router], connect_timeout_ms=5000))
    try:
        text = status_during_an_alert(session, station_file, 1)
        as_json = status_during_an_alert(session, station_file, 11, "--json")
        # a status started after the alerts were put learns of them from RecorderStats
        command = ["status", "--config", str(station_file), "--listen-s", "2.5", "--json"]
        later = boltwatch(*command)
    finally:
        session.close()
        recorder.finish()

    assert text.returncode == 0, text.stderr
    block = text.stdout.split("station st1\n", 1)[1]
    lines = {line[:16].strip(): line[16:] for line in block.splitlines()}
    assert lines["quality alert"].startswith("nok_run: program 2: 3 NOK in a row (alert at 3), ")
    assert lines["quality alert"].endswith(" s ago")  # the first round: the run alone

    assert as_json.returncode == 0, as_json.stderr
    alert = json.loads(as_json.stdout)["stations"]["st1"]["quality_alert"]
    assert (alert["program_id"], alert["kind"], alert["figure"]) == (2, "nok_run", None)
    # the second round's 2nd NOK was the 5th of the last 20 (nok_rate, still active), its
    # 3rd NOK started the run again: the newest active is the run, two are active
    assert (alert["value"], alert["limit"], alert["runs"]) == (3.0, 3.0, 3)
    assert alert["active_alerts"] == 2

    assert later.returncode == 0, later.stderr
    heard_later = json.loads(later.stdout)["stations"]["st1"]["quality_alert"]
    assert heard_later is not None, "an alert put before status listened is not shown"
    assert (heard_later["kind"], heard_later["active_alerts"]) == ("nok_run", 2)
