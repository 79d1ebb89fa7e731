"""The recorder's quality alert: real TighteningResults on zenoh into a real
recorder; the alert comes back on ``boltwatch/st1/quality/alert``, once when a condition
starts, once when it clears; its Cpk checked against numpy; recorded in the MCAP files."""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
import zenoh
from mcap.reader import make_reader

from shared.config import LoadedStation, load_station
from shared.contract import (
    JudgedFigure,
    QualityAlert,
    TighteningResult,
    Verdict,
    channels,
    decode,
    encode,
)
from tests.support import factories
from tests.support.live_recorder import (
    RunningRecorder,
    has_subscribers,
    wait_until,
    write_station_file,
)

S_NS = 1_000_000_000
TORQUE = (180.0, 240.0)
ANGLE_MIN = 35.0
FORCE = (53000.0, 59000.0)  # the preload window
QUALITY = {"cpk_min": 1.33, "window_runs": 10, "min_runs": 5, "nok_run": 3}


@pytest.fixture
def station(tmp_path: Path, endpoint: str) -> LoadedStation:
    path = write_station_file(
        tmp_path / "station.toml", tmp_path / "recordings", listen=[endpoint], quality=QUALITY
    )
    return load_station(path)


def result(run_id: int, time_ns: int, force_n: float, verdict: Verdict = "OK") -> TighteningResult:
    """A result of program 1: torque and angle steady, the given preload, the given verdict."""
    return factories.result(
        run_id,
        time_ns=time_ns,
        final_torque_nm=JudgedFigure(210.0 + 0.1 * (run_id % 3), *TORQUE, "ok"),
        final_angle_deg=JudgedFigure(47.0 + 0.05 * (run_id % 2), ANGLE_MIN, None, "ok"),
        final_force_n=JudgedFigure(force_n, *FORCE, "ok" if verdict == "OK" else "low"),
        result=verdict,
        nok_reasons="" if verdict == "OK" else f"preload low: {force_n:.1f}",
    )


def cpk(values: list[float], low: float, high: float) -> float:
    mean, sigma = float(np.mean(values)), float(np.std(values, ddof=1))
    return min(high - mean, mean - low) / (3 * sigma)


@pytest.fixture
def heard(publisher_session: zenoh.Session) -> Iterator[list[QualityAlert]]:
    alerts: list[QualityAlert] = []
    subscriber = publisher_session.declare_subscriber(
        channels.QUALITY_ALERT.key("st1"),
        lambda sample: alerts.append(decode(QualityAlert, sample.payload.to_bytes())),
    )
    yield alerts
    subscriber.undeclare()


def put_results(session: zenoh.Session, results: list[TighteningResult]) -> None:
    publisher = session.declare_publisher(
        channels.RESULTS.key("st1"), congestion_control=zenoh.CongestionControl.BLOCK
    )
    wait_until(lambda: has_subscribers(publisher), "the recorder")
    for one in results:
        publisher.put(encode(one))
    publisher.undeclare()


def recorded_alerts(station: LoadedStation) -> list[QualityAlert]:
    alerts = []
    for path in sorted(station.recordings_folder.glob("st1/**/*.mcap")):
        with path.open("rb") as handle:
            for _schema, channel, message in make_reader(handle).iter_messages():
                if channel.topic == channels.QUALITY_ALERT.key("st1"):
                    alerts.append(decode(QualityAlert, message.data))
    return sorted(alerts, key=lambda alert: alert.time_ns)


def test_a_bad_preload_spread_raises_one_cpk_alert_with_numpys_cpk(
    station: LoadedStation,
    recorder: RunningRecorder,
    publisher_session: zenoh.Session,
    heard: list[QualityAlert],
) -> None:
    """8 steady preloads (Cpk ~ 10), then 8 OK ones alternating near both bounds (Cpk < 1):
    one cpk_low alert for the preload at the first result whose rolling Cpk is below 1.33,
    none while it lasts; torque and angle (steady) and the NOK checks (all OK) stay quiet."""
    t0 = time.time_ns() - 60 * S_NS
    steady = [56000.0 + 20.0 * ((n % 3) - 1) for n in range(8)]
    spread = [53400.0 if n % 2 else 58600.0 for n in range(8)]
    preloads = steady + spread
    results = [result(n + 1, t0 + n * S_NS, force) for n, force in enumerate(preloads)]
    put_results(publisher_session, results)
    quality = recorder.service.quality
    assert quality is not None
    wait_until(lambda: len(heard) >= 1, "the quality alert")

    # numpy: the first result after which the last 10 preloads' Cpk is below 1.33
    first = next(
        n
        for n in range(len(preloads))
        if n + 1 >= QUALITY["min_runs"]
        and cpk(preloads[max(0, n - 9) : n + 1], *FORCE) < QUALITY["cpk_min"]
    )
    expected = cpk(preloads[max(0, first - 9) : first + 1], *FORCE)
    alert = heard[0]
    assert (alert.kind, alert.figure, alert.active) == ("cpk_low", "preload", True)
    assert (alert.station, alert.program_id, alert.time_ns) == ("st1", 1, results[first].time_ns)
    assert alert.value == pytest.approx(expected, rel=1e-12)
    assert (alert.limit, alert.runs) == (1.33, min(first + 1, 10))
    assert "preload Cpk" in alert.text and "window [53000, 59000]" in alert.text

    recorder.finish()  # every result filed: what was recorded is every alert put
    assert [(a.kind, a.figure, a.active) for a in recorded_alerts(station)] == [
        ("cpk_low", "preload", True)
    ]
    assert quality.alerts == 1 and len(heard) == 1


def test_noks_in_a_row_and_noks_among_the_last_n_alert_when_they_start_and_clear(
    station: LoadedStation,
    recorder: RunningRecorder,
    publisher_session: zenoh.Session,
    heard: list[QualityAlert],
) -> None:
    """OK, NOK x4, OK (clears the run), NOK x3 (the run again; the 5th NOK of the last 20
    before it: nok_rate); a repeated result counts once. One preload throughout: σ = 0, no
    Cpk, no cpk alert."""
    t0 = time.time_ns() - 60 * S_NS
    verdicts: list[Verdict] = ["OK", "NOK", "NOK", "NOK", "NOK", "OK", "NOK", "NOK", "NOK"]
    results = [result(n + 1, t0 + n * S_NS, 52000.0, v) for n, v in enumerate(verdicts)]
    repeated = [*results[:2], results[1], *results[2:]]  # run 2 heard twice
    put_results(publisher_session, repeated)
    wait_until(lambda: len(heard) >= 4, "four quality alerts")
    said = [(a.kind, a.active, a.value, a.limit, a.runs, a.time_ns) for a in heard]
    assert said == [
        ("nok_run", True, 3.0, 3.0, 3, results[3].time_ns),  # the third NOK in a row
        ("nok_run", False, 0.0, 3.0, 0, results[5].time_ns),  # the OK clears it
        ("nok_rate", True, 5.0, 5.0, 7, results[6].time_ns),  # 5 NOK of the last 7 (of 20)
        ("nok_run", True, 3.0, 3.0, 3, results[8].time_ns),  # and the run returns
    ]
    assert all(a.figure is None and a.program_id == 1 for a in heard)
    assert heard[0].text == "program 1: 3 NOK in a row (alert at 3)"
    assert heard[2].text == "program 1: 5 NOK of the last 7 runs (alert at 5 of 20)"
    recorder.finish()
    assert [(a.kind, a.active) for a in recorded_alerts(station)] == [
        ("nok_run", True),
        ("nok_run", False),
        ("nok_rate", True),
        ("nok_run", True),
    ]
