"""docker-compose.tls.yml run on loopback: the commands compose would run, with the identities.

Each service runs with the exact arguments of its merged command, in a copy of
what its container sees, the router and the CAN ports moved to free ones on
loopback (tests/support/compose_line.py); health checks run as the containers
run them, with that container's identity.

The station's predictor is in its acquisition (placement "edge"): no predictor
container runs, ``boltwatch health predictor`` is answered by acquisition-st1's
token, and its decisions reach the line under st1-acquisition's certificate.
"""

from __future__ import annotations

import contextlib
import json
import shutil
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import zenoh

from services.cli.station_supervisor import stop_process
from shared.contract import RunSummary, StopDecision, channels, decode, keys
from shared.errors import BoltwatchError
from tests.support.compose_line import NOT_ALIVE, TLS_STATIONS, ComposeLine, running_line
from tests.support.live_recorder import has_subscribers
from tests.support.router_process import boltwatch

pytestmark = [
    pytest.mark.system,
    pytest.mark.skipif(shutil.which("openssl") is None, reason="needs the openssl CLI"),
]

RUNNING = ("router", "acquisition-st1", "rig-st1", "recorder", "dashboard")
HEALTHY_WITHIN_S = 60.0

HEARD_WITHIN_S = 60.0
DECISION = channels.DECISION.key("st1")
SAMPLES = channels.SAMPLE_BATCHES.key("st1")  # an edge station: its samples in batches
RUNS = channels.RUNS.key("st1")


@pytest.fixture
def line(tmp_path: Path) -> Iterator[ComposeLine]:
    with running_line(tmp_path, RUNNING) as started:
        yield started


def test_every_service_is_healthy_with_its_own_identity_and_status_sees_them(
    line: ComposeLine,
) -> None:
    """As compose waits on health: retry each container's check until it passes; the
    station's predictor is alive though no predictor runs (acquisition-st1 holds its token:
    ``health predictor`` fails once the acquisition stops); the operator's ``boltwatch
    status`` with the line-monitor identity sees st1's services, its predictor among them."""
    line.session("router").close()  # the router takes TLS sessions now: 2 is a real failure
    assert not any(name.startswith("predictor") for name in line.services), "edge layout"
    line.wait_healthy(RUNNING, HEALTHY_WITHIN_S)
    # Its predictor's token is declared before its own: healthy acquisition, alive predictor.
    predictor = line.health("acquisition-st1", service="predictor")
    assert predictor.returncode == 0, f"{predictor.stdout}{predictor.stderr}"
    monitor_file = line.files("recorder", identity="line-monitor").host(
        f"{TLS_STATIONS}/station1.toml"
    )
    status = boltwatch("status", "--config", str(monitor_file), "--json", timeout_s=60, check=True)
    services = json.loads(status.stdout)["stations"]["st1"]["services"]
    alive = {service for service, up in services.items() if up}
    assert {"acquisition", "predictor", "rig", "recorder"} <= alive
    stop_process(line.processes["acquisition-st1"], grace_s=10.0)
    deadline = time.monotonic() + HEALTHY_WITHIN_S
    while (gone := line.health("acquisition-st1", service="predictor")).returncode != NOT_ALIVE:
        assert gone.returncode == 0, f"{gone.stdout}{gone.stderr}"
        assert time.monotonic() < deadline, "st1's predictor outlived its acquisition"
        time.sleep(0.5)


def decoded(kind: type[Any], payloads: list[bytes]) -> list[Any]:
    """The payloads that are ``kind`` messages (hand-put test markers are not)."""
    messages = []
    for payload in payloads:
        with contextlib.suppress(BoltwatchError):
            messages.append(decode(kind, payload))
    return messages


def test_data_flows_and_only_st1s_acquisition_may_decide_for_st1(line: ComposeLine) -> None:
    """acquisition-st1's edge predictor stops the tool and its decisions and run summaries
    reach the line under st1-acquisition's certificate; another station's acquisition
    certificate mounted in acquisition-st1 cannot put st1's decision or samples."""
    heard: dict[str, list[bytes]] = {}
    arrived = threading.Condition()

    def on_sample(sample: zenoh.Sample) -> None:
        with arrived:
            heard.setdefault(str(sample.key_expr), []).append(sample.payload.to_bytes())
            arrived.notify_all()

    def wait_for(what: str, condition: Any) -> None:
        with arrived:
            if not arrived.wait_for(lambda: condition(heard), timeout=HEARD_WITHIN_S):
                logs = "\n".join(f"-- {n}:\n{line.log(n)}" for n in RUNNING)
                raise AssertionError(f"never heard {what} (heard {sorted(heard)})\n{logs}")

    def stopped_by_the_edge_predictor(h: dict[str, list[bytes]]) -> bool:
        reasons = {d.reason for d in decoded(StopDecision, h.get(DECISION, []))}
        return any(r.stop_reason in reasons for r in decoded(RunSummary, h.get(RUNS, [])))

    sessions: list[zenoh.Session] = []
    try:
        # The operator's identity, as `boltwatch status` would use it (line-monitor).
        monitor = line.session("recorder", identity="line-monitor")
        sessions.append(monitor)
        subscriber = monitor.declare_subscriber(keys.station_key("st1", "*"), on_sample)
        recorder = channels.RECORDER.key("st1")
        # The acquisition's and the recorder's own certificates may put their keys.
        wait_for("st1's samples and recorder stats", lambda h: SAMPLES in h and recorder in h)
        # The predictor in acquisition-st1 decided, stopped the tool, summed the run up.
        wait_for("a run stopped by st1's edge predictor", stopped_by_the_edge_predictor)

        impostor = line.session("acquisition-st1", identity="st2-acquisition")
        legit = line.session("acquisition-st1")
        sessions += [impostor, legit]
        decisions = monitor.declare_subscriber(channels.DECISION.key("*"), on_sample)
        publisher = legit.declare_publisher(DECISION)
        own_key = channels.DECISION.key("st2")  # what st2's acquisition may decide
        own = impostor.declare_publisher(own_key)
        deadline = time.monotonic() + HEARD_WITHIN_S
        while not (has_subscribers(publisher) and has_subscribers(own)):
            assert time.monotonic() < deadline, "no subscriber matched the decisions"
            time.sleep(0.05)
        # First: if they got through they would land first.
        impostor.put(DECISION, b"impostor-decision")
        impostor.put(SAMPLES, b"impostor-sample")
        own.put(b"st2-own")  # after them on the same link: heard, so those before were handled
        publisher.put(b"st1-acquisition")
        wait_for("st2's own decision", lambda h: b"st2-own" in h.get(own_key, []))
        wait_for("st1-acquisition's decision", lambda h: b"st1-acquisition" in h.get(DECISION, []))
        with arrived:
            assert b"impostor-decision" not in heard[DECISION], "st2's acquisition decided for st1"
            assert b"impostor-sample" not in heard[SAMPLES], "st2's acquisition put st1's samples"
        own.undeclare()
        decisions.undeclare()
        publisher.undeclare()
        subscriber.undeclare()
    finally:
        for session in sessions:
            session.close()
