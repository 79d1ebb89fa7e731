"""The predictor service on real zenoh: samples and tool states in, messages out."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import zenoh

from services.predictor.service import PredictorService
from services.recorder.testing import free_port
from shared import codec, keys
from shared.config import LoadedStation, load_station
from shared.messages import (
    Intensity,
    RunSummary,
    Sample,
    StickSlipEvent,
    StopDecision,
    ToolState,
)
from shared.zenoh_session import zenoh_config
from tests.unit.predictor.synthetic import staircase

REPO = Path(__file__).resolve().parents[3]
TARGET_N = 30_400.0


@pytest.fixture
def endpoint() -> str:
    return f"tcp/127.0.0.1:{free_port()}"


@pytest.fixture
def station(tmp_path: Path, endpoint: str) -> LoadedStation:
    path = tmp_path / "station.toml"
    path.write_text(
        f"""
[station]
id = "pt1"
tool_id = 3
joint = "{REPO / "config/joints/paper-section-5-2.toml"}"
[can]
interface = "virtual"
channel = "pt1"
dbc = "{REPO / "config/can/station.dbc"}"
[zenoh]
mode = "peer"
listen = ["{endpoint}"]
[[programs]]
id = 1
name = "test"
target_force_n = {TARGET_N}
motor_speed_rad_s = 0.5
start_force_n = 10000.0
max_torque_nm = 320.0
max_force_n = 75000.0
max_angle_deg = 150.0
max_time_s = 6.0
[predictor]
window_samples = 5
[recorder]
folder = "{tmp_path / "rec"}"
"""
    )
    return load_station(path)


@pytest.fixture
def service(station: LoadedStation) -> Iterator[PredictorService]:
    session = zenoh.open(zenoh_config("peer", listen=station.config.zenoh.listen))
    stop = threading.Event()
    predictor = PredictorService(session, station)
    worker = threading.Thread(target=predictor.work, args=(stop,), daemon=True)
    worker.start()
    try:
        yield predictor
    finally:
        stop.set()
        predictor.wake()
        worker.join(5.0)
        predictor.close()
        session.close()
    assert not worker.is_alive()


def wait_for_token(session: zenoh.Session, key: str) -> None:
    for _ in range(100):
        if list(session.liveliness().get(key)):
            return
        time.sleep(0.05)
    raise AssertionError(f"no liveliness token {key}")


def wait_for_subscriber(publisher: zenoh.Publisher) -> None:
    for _ in range(200):
        status: Any = publisher.matching_status  # stubs say bool; it is a MatchingStatus
        if status.matching:
            return
        time.sleep(0.02)
    raise AssertionError(f"no subscriber for {publisher.key_expr}")


def test_service_publishes_events_decision_and_summary(
    service: PredictorService, endpoint: str
) -> None:
    trace = staircase(torque_noise_nm=0.2, force_noise_n=30.0)
    with zenoh.open(zenoh_config("peer", connect=[endpoint])) as session:
        wait_for_token(session, keys.health_key("pt1", "predictor"))
        received = session.declare_subscriber(
            "boltwatch/pt1/**", zenoh.handlers.FifoChannel(10_000)
        )
        tool = session.declare_publisher(keys.station_key("pt1", keys.TOOL))
        samples = session.declare_publisher(keys.station_key("pt1", keys.SAMPLES))
        start_ns = 1_700_000_000_000_000_000
        for publisher in (tool, samples):  # the predictor's subscriber must be known here
            wait_for_subscriber(publisher)

        def state(name: str, at_ns: int) -> bytes:
            return codec.encode(ToolState("pt1", 42, 3, 1, name, at_ns))  # type: ignore[arg-type]

        samples.put(codec.encode(Sample("pt1", 41, 0, start_ns, 1.0, 0.0, 1.0)))  # no run: dropped
        tool.put(state("running", start_ns))
        for i, (t, torque, force, angle) in enumerate(trace.rows()):
            sample = Sample("pt1", 42, i, start_ns + round(t * 1e9), torque, angle, force)
            samples.put(codec.encode(sample))
        tool.put(state("done", start_ns + 2_000_000_000))
        by_topic: dict[str, list[bytes]] = {}
        deadline = time.monotonic() + 30.0
        while keys.RUNS not in by_topic and time.monotonic() < deadline:
            message = received.try_recv()
            if message is None:
                time.sleep(0.01)
                continue
            topic = str(message.key_expr).rsplit("/", 1)[-1]
            by_topic.setdefault(topic, []).append(message.payload.to_bytes())
        received.undeclare()
        tool.undeclare()
        samples.undeclare()
    events = [codec.decode(StickSlipEvent, p) for p in by_topic.get(keys.EVENTS, [])]
    intensities = [codec.decode(Intensity, p) for p in by_topic.get(keys.INTENSITY, [])]
    decisions = [codec.decode(StopDecision, p) for p in by_topic.get(keys.DECISION, [])]
    (summary,) = [codec.decode(RunSummary, p) for p in by_topic[keys.RUNS]]
    assert len(events) == len(trace.plateaus_n) - 1
    assert len(intensities) == len(events)
    assert events[-1].predictions and events[-1].run_id == 42
    (decision,) = decisions
    assert decision.reason == "plateau_closest"
    assert decision.force_n == pytest.approx(30_056.0, abs=150.0)
    assert summary.stop_reason == "plateau_closest"
    assert summary.events == len(events)
    assert summary.samples == len(trace.rows())
    assert summary.error_pct is not None
    assert summary.reached_force_n == pytest.approx(trace.force_n[-1])
    assert service.dropped_samples == 1
