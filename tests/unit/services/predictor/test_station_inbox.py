"""StationInbox on real zenoh sessions: served stations only, in order, failures not swallowed,
and zenoh's receive threads keep their Python thread state between callbacks."""

from __future__ import annotations

import subprocess
import sys
import threading
import time

import pytest
import zenoh

from services.predictor.station_inbox import StationInbox
from shared.contract import channels, keys
from shared.runtime import zenoh_config
from tests.support.live_recorder import free_port, wait_until
from tests.support.paths import REPO

Handled = list[tuple[str, str, bytes]]


def publishers(session: zenoh.Session, station_id: str) -> dict[str, zenoh.Publisher]:
    found = {
        topic: session.declare_publisher(keys.station_key(station_id, topic))
        for topic in (channels.SAMPLES.topic, channels.TOOL.topic)
    }
    for publisher in found.values():
        wait_until(lambda p=publisher: bool(p.matching_status.matching), "the inbox")  # type: ignore[misc]
    return found


def test_only_served_stations_arrive_in_publication_order(
    sessions: tuple[zenoh.Session, zenoh.Session],
) -> None:
    served, feeding = sessions
    handled: Handled = []
    inbox = StationInbox(served, ["a1", "a2"], lambda *message: handled.append(message))
    try:
        feeds = {s: publishers(feeding, s) for s in ("a1", "a2")}
        unserved = feeding.declare_publisher(channels.SAMPLES.key("a3"))
        expected: Handled = []
        for i in range(200):
            for station_id, topics in feeds.items():
                topic = channels.TOOL.topic if i % 50 == 0 else channels.SAMPLES.topic
                topics[topic].put(f"{station_id}-{i}".encode())
                expected.append((station_id, topic, f"{station_id}-{i}".encode()))
            unserved.put(b"never")
        wait_until(lambda: len(handled) >= len(expected), "every message")
        time.sleep(0.2)  # anything more (a3) would arrive now
    finally:
        inbox.close()
    for station_id in ("a1", "a2"):
        assert [m for m in handled if m[0] == station_id] == [
            m for m in expected if m[0] == station_id
        ]
    assert len(handled) == len(expected)


def test_a_handler_error_ends_serve_with_it_and_later_messages_are_counted(
    sessions: tuple[zenoh.Session, zenoh.Session],
) -> None:
    served, feeding = sessions

    def handle(_station: str, _topic: str, payload: bytes) -> None:
        if payload == b"bad":
            raise ValueError("handler broke on 'bad'")

    inbox = StationInbox(served, ["a1"], handle)
    stop = threading.Event()
    failure: list[BaseException] = []

    def serve() -> None:
        try:
            inbox.serve(stop)
        except BaseException as err:
            failure.append(err)

    worker = threading.Thread(target=serve, daemon=True)
    worker.start()
    try:
        samples = publishers(feeding, "a1")[channels.SAMPLES.topic]
        samples.put(b"good")
        samples.put(b"bad")
        samples.put(b"after")
        worker.join(10.0)
        wait_until(lambda: inbox.lost_after_failure == 1, "the message after the failure")
    finally:
        inbox.close()
    assert not worker.is_alive()
    assert [str(err) for err in failure] == ["handler broke on 'bad'"]


def test_serve_returns_once_stopped_and_woken(
    sessions: tuple[zenoh.Session, zenoh.Session],
) -> None:
    inbox = StationInbox(sessions[0], ["a1"], lambda *_: None)
    stop = threading.Event()
    worker = threading.Thread(target=inbox.serve, args=(stop,), daemon=True)
    worker.start()
    inbox.wake()  # a wake without stop: serve goes on waiting
    time.sleep(0.1)
    assert worker.is_alive()
    stop.set()
    inbox.wake()
    worker.join(5.0)
    inbox.close()
    assert not worker.is_alive()


class UnpinnedInbox(StationInbox):
    keep_thread_states = False


def calls_seen_before(keep_thread_states: bool) -> list[int]:
    """For 50 callbacks, how many earlier calls a threading.local remembered. A
    threading.local lives in the thread state: it survives from one callback to
    the next only if the thread state does (CPython makes a new one otherwise)."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    local = threading.local()
    seen_before: list[int] = []

    def handle(_station: str, _topic: str, _payload: bytes) -> None:
        seen_before.append(getattr(local, "calls", 0))
        local.calls = getattr(local, "calls", 0) + 1

    inbox_type = StationInbox if keep_thread_states else UnpinnedInbox
    with (
        zenoh.open(zenoh_config("peer", listen=[endpoint])) as served,
        zenoh.open(zenoh_config("peer", connect=[endpoint])) as feeding,
    ):
        inbox = inbox_type(served, ["a1"], handle)
        try:
            samples = publishers(feeding, "a1")[channels.SAMPLES.topic]
            for _ in range(50):
                samples.put(b"x")
                time.sleep(0.002)  # one callback at a time
            wait_until(lambda: len(seen_before) == 50, "fifty callbacks")
        finally:
            inbox.close()
    return seen_before


@pytest.mark.parametrize("keep", [True, False])
def test_receive_threads_keep_their_python_thread_state(keep: bool) -> None:
    """In a fresh process each: zenoh's receive threads live as long as the process,
    so a thread state kept by an earlier test would still be there."""
    script = (
        "from tests.unit.services.predictor.test_station_inbox import calls_seen_before; "
        f"print(max(calls_seen_before({keep})))"
    )
    done = subprocess.run(
        [sys.executable, "-c", script],
        check=False,
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    assert (int(done.stdout.strip()) > 0) is keep


def test_close_waits_for_the_callback_in_progress(
    sessions: tuple[zenoh.Session, zenoh.Session],
) -> None:
    """zenoh's undeclare does not wait for a running callback; close() must, or the
    service would undeclare publishers (and close the session) under a handler."""
    served, feeding = sessions
    started = threading.Event()
    finished: list[float] = []

    def slow(*_message: object) -> None:
        started.set()
        time.sleep(0.5)
        finished.append(time.monotonic())

    inbox = StationInbox(served, ["a1"], slow)
    publishers(feeding, "a1")[channels.SAMPLES.topic].put(b"x")
    assert started.wait(10.0)
    inbox.close()
    closed_at = time.monotonic()
    assert finished and finished[0] <= closed_at
