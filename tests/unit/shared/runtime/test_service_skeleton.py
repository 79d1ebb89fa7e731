"""A service's skeleton stops what it owns in one order, whatever order it was declared in:
input, work, output, health tokens, session, devices; and runs the work as a service."""

from __future__ import annotations

import functools
import os
import signal
import threading
import time
from collections.abc import Iterator

import pytest
import zenoh

from shared.contract import channels, keys
from shared.errors import BoltwatchError
from shared.runtime import ServiceSkeleton, Stop, zenoh_config
from tests.support.live_recorder import WAIT_S, free_port

TOKEN_KEY = keys.health_key("st1", "tester")


@pytest.fixture
def endpoint() -> str:
    return f"tcp/127.0.0.1:{free_port()}"


@pytest.fixture
def observer(endpoint: str) -> Iterator[zenoh.Session]:
    """A second session on loopback that sees the skeleton's token (it listens, the
    skeleton's session connects: the skeleton can close first)."""
    with zenoh.open(zenoh_config("peer", listen=[endpoint])) as session:
        yield session


def token_seen(observer: zenoh.Session) -> bool:
    replies = observer.liveliness().get(TOKEN_KEY, timeout=5)
    return any(reply.ok is not None for reply in replies)


def token_gone(observer: zenoh.Session) -> bool:
    """Whether the observer stops seeing the token (an undeclare travels: a bounded wait)."""
    deadline = time.monotonic() + WAIT_S
    while token_seen(observer):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.02)
    return True


def test_the_stages_run_in_their_order_whatever_order_they_were_registered_in() -> None:
    ran: list[Stop] = []
    with ServiceSkeleton("tester") as skeleton:
        for stage in sorted(Stop, reverse=True):
            skeleton.on_stop(stage, functools.partial(ran.append, stage))
    assert ran == [Stop.INPUT, Stop.WORK, Stop.OUTPUT, Stop.HEALTH, Stop.SESSION, Stop.DEVICE]


def test_within_a_stage_the_last_registered_goes_first_and_a_second_close_does_nothing() -> None:
    ran: list[str] = []
    skeleton = ServiceSkeleton("tester")
    skeleton.on_stop(Stop.OUTPUT, lambda: ran.append("queue flushed"))
    skeleton.on_stop(Stop.OUTPUT, lambda: ran.append("link closed"))
    skeleton.close()
    skeleton.close()
    assert ran == ["link closed", "queue flushed"]


def test_a_close_that_fails_does_not_keep_the_later_stages_from_running() -> None:
    ran: list[str] = []

    def fails() -> None:
        raise OSError("disk gone")

    skeleton = ServiceSkeleton("tester")
    skeleton.on_stop(Stop.DEVICE, lambda: ran.append("bus closed"))
    skeleton.on_stop(Stop.HEALTH, lambda: ran.append("token undeclared"))
    skeleton.on_stop(Stop.WORK, fails)
    with pytest.raises(OSError, match="disk gone"):
        skeleton.close()
    assert ran == ["token undeclared", "bus closed"]


def test_the_health_token_stays_while_input_stops_and_output_flushes_then_goes_before_the_session(
    endpoint: str, observer: zenoh.Session
) -> None:
    """What ``boltwatch up`` and ``status`` rely on: a service looks alive on the line until
    its work is finished and flushed, and its session is still open to say it is gone."""
    seen: dict[str, bool] = {}
    with ServiceSkeleton("tester") as skeleton:
        skeleton.own_session(zenoh.open(zenoh_config("peer", connect=[endpoint])))
        # declared in the "wrong" order: session first, token before the input and output
        skeleton.health_token("st1", "tester")
        skeleton.on_stop(Stop.INPUT, lambda: seen.update(input=token_seen(observer)))
        subscriber = skeleton.subscriber(channels.DECISION.key("st1"), lambda _sample: None)
        publisher = skeleton.publisher(channels.RUNS, "st1")
        skeleton.on_stop(Stop.OUTPUT, lambda: seen.update(output=token_seen(observer)))
        skeleton.on_stop(Stop.SESSION, lambda: seen.update(gone=token_gone(observer)))
        assert token_seen(observer)
    assert seen == {"input": True, "output": True, "gone": True}
    assert skeleton.session.is_closed()
    for entity in (subscriber, publisher):  # undeclared: using it again is refused
        with pytest.raises(zenoh.ZError):
            entity.undeclare()


def test_the_publisher_has_its_channels_options() -> None:
    with ServiceSkeleton("tester", zenoh.open(zenoh_config("peer"))) as skeleton:
        decision = skeleton.publisher(channels.DECISION, "st1")
        assert decision.key_expr == channels.DECISION.key("st1")
        assert decision.priority == zenoh.Priority.REAL_TIME
        assert decision.congestion_control == zenoh.CongestionControl.BLOCK


def test_one_service_has_one_session() -> None:
    with (
        ServiceSkeleton("tester", zenoh.open(zenoh_config("peer"))) as skeleton,
        pytest.raises(RuntimeError, match="one zenoh session"),
    ):
        skeleton.own_session(skeleton.session)
    with pytest.raises(RuntimeError, match="no zenoh session"):
        ServiceSkeleton("tester").health_token("st1", "tester")


def test_run_is_0_on_sigterm_and_1_when_the_work_fails() -> None:
    woken = threading.Event()

    def waits(stop: threading.Event) -> None:
        os.kill(os.getpid(), signal.SIGTERM)  # handled on the main thread: stop is set
        stop.wait()

    def fails(_stop: threading.Event) -> None:
        raise BoltwatchError("the CAN bus is gone")

    with ServiceSkeleton("tester") as skeleton:
        assert skeleton.run(waits, woken.set) == 0
    assert woken.is_set()
    with ServiceSkeleton("tester") as skeleton:
        assert skeleton.run(fails) == 1
