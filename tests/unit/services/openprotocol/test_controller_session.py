"""The integrator's session against a scripted controller on real TCP, answering as real ones do.

The controller side is bytes written by hand from the specification's
layouts (20-byte header, data, NUL), not our codec: what it answers is
scripted per request, and it may write an answer and the next message in one
TCP write, or a message one byte at a time.
"""

from __future__ import annotations

import contextlib
import socket
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from services.openprotocol.bridge_counts import BridgeCounts
from services.openprotocol.controller_link import ControllerLink, LinkLostError
from services.openprotocol.controller_session import ControllerSession, SessionStoppedError
from shared.openprotocol import (
    AlarmStatus,
    AlarmSubscribe,
    CommandAccepted,
    DataSubscribe,
    Dialect,
    ResultSubscribe,
    trace_extra_data,
)

KEEP_ALIVE_S = 0.5


def wire(mid: int, data: str = "", revision: int = 1) -> bytes:
    """A message as the specification writes it: length, MID, revision, spaces, data, NUL."""
    header = f"{20 + len(data):04d}{mid:04d}{revision:03d}" + " " * 9
    return (header + data).encode("latin-1") + b"\x00"


#: 0076 rev 1: 01 alarm status, 02 error code (4), 03 controller ready, 04 tool ready, 05 time
ALARM_STATUS = wire(76, "011" + "02E404" + "031" + "041" + "052026-11-24:10:00:00")


class ScriptedController:
    """Accepts one integrator; answers each request by its MID with scripted bytes."""

    def __init__(self, answers: dict[int, Callable[[], list[bytes]]]) -> None:
        self.answers = answers
        self._server = socket.create_server(("127.0.0.1", 0))
        self.port = int(self._server.getsockname()[1])
        self.heard: list[int] = []
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._thread.start()

    def _serve(self) -> None:
        client, _ = self._server.accept()
        client.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        buffer = b""
        with client:
            while True:
                try:
                    chunk = client.recv(4096)
                except OSError:
                    return
                if not chunk:
                    return
                buffer += chunk
                while len(buffer) >= 20:
                    length = int(buffer[:4])
                    if len(buffer) < length + 1:
                        break
                    mid = int(buffer[4:8])
                    buffer = buffer[length + 1 :]
                    self.heard.append(mid)
                    for write in self.answers.get(mid, list)():
                        client.sendall(write)
                        time.sleep(0.01)

    def close(self) -> None:
        self._server.close()


@pytest.fixture
def counts() -> BridgeCounts:
    return BridgeCounts("st1", "127.0.0.1")


@contextlib.contextmanager
def session_to(
    controller: ScriptedController,
    counts: BridgeCounts,
    stop: threading.Event | None = None,
    keep_alive_s: float = KEEP_ALIVE_S,
) -> Iterator[tuple[ControllerSession, list[Any]]]:
    pushed: list[Any] = []
    with ControllerLink("127.0.0.1", controller.port, 2 * keep_alive_s) as link:
        yield ControllerSession(link, counts, keep_alive_s, Dialect(), pushed.append, stop), pushed
    controller.close()


def trace_subscription(revision: int) -> DataSubscribe:
    return DataSubscribe(mid=900, extra_data=trace_extra_data([2, 1]), revision=revision)


@pytest.mark.parametrize("named", [900, 8])
def test_a_0900_subscription_is_accepted_by_a_0005_naming_either_mid(
    named: int, counts: BridgeCounts
) -> None:
    """The specification: "MID 0005 Command accepted with the MID subscribed for" (0900);
    some controllers name 0008 itself."""
    controller = ScriptedController({8: lambda: [wire(5, f"{named:04d}")]})
    with session_to(controller, counts) as (session, _):
        assert session.subscribe(trace_subscription, 1) == 1
    assert counts.controller_errors == 0 and counts.last_error is None


def test_what_shares_a_read_with_an_answer_is_pushed_not_lost(counts: BridgeCounts) -> None:
    """0005 for 0070 and the 0076 right after it, in one TCP write."""
    controller = ScriptedController({70: lambda: [wire(5, "0070") + ALARM_STATUS]})
    with session_to(controller, counts) as (session, pushed):
        assert session.subscribe(lambda rev: AlarmSubscribe(revision=rev), 1) == 1
        session.poll(0.2)
        assert [type(message) for message in pushed] == [AlarmStatus]
        assert pushed[0].error_code == "E404" and pushed[0].alarm_active


def test_an_answer_written_a_byte_at_a_time_is_taken(counts: BridgeCounts) -> None:
    answer = wire(5, "0060")
    controller = ScriptedController({60: lambda: [answer[i : i + 1] for i in range(len(answer))]})
    with session_to(controller, counts) as (session, _):
        assert session.subscribe(lambda rev: ResultSubscribe(revision=rev), 1) == 1


def test_a_revision_fall_back_is_no_fault(counts: BridgeCounts) -> None:
    refusals = iter([[wire(4, "006097")], [wire(5, "0060")]])
    controller = ScriptedController({60: lambda: next(refusals)})
    with session_to(controller, counts) as (session, _):
        assert session.subscribe(lambda rev: ResultSubscribe(revision=rev), 2) == 1
    assert counts.controller_errors == 0 and counts.last_error is None


def test_an_optional_subscription_never_answered_is_counted_and_the_session_goes_on(
    counts: BridgeCounts,
) -> None:
    controller = ScriptedController({9999: lambda: [wire(9999)]})
    with session_to(controller, counts) as (session, _):
        started = time.monotonic()
        assert session.subscribe(lambda rev: AlarmSubscribe(revision=rev), 1) is None
        assert time.monotonic() - started >= session.dead_after_s
        assert counts.last_error is not None and "no answer to MID 0070" in counts.last_error
        with pytest.raises(LinkLostError, match="no answer to MID 0060"):
            session.subscribe(lambda rev: ResultSubscribe(revision=rev), 1, required=True)


def test_stopping_while_an_answer_is_awaited_ends_the_wait_at_once(counts: BridgeCounts) -> None:
    stop = threading.Event()
    controller = ScriptedController({})
    with session_to(controller, counts, stop, keep_alive_s=10.0) as (session, _):
        threading.Timer(0.2, stop.set).start()
        started = time.monotonic()
        with pytest.raises(SessionStoppedError):
            session.request(ResultSubscribe(), set())
        assert time.monotonic() - started < session.dead_after_s / 2, "not the dead-link time"
    assert counts.last_error is None


def test_a_late_acceptance_is_taken_quietly(counts: BridgeCounts) -> None:
    controller = ScriptedController({60: lambda: [wire(5, "0070"), wire(5, "0060")]})
    with session_to(controller, counts) as (session, pushed):
        assert isinstance(session.request(ResultSubscribe(), set()), CommandAccepted)
        assert pushed == [] and counts.last_error is None
