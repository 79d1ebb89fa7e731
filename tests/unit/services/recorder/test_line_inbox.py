"""LineInbox on real zenoh sessions: everything kept in order, a full inbox holds the
publisher back instead of dropping, and what arrives after close is counted."""

from __future__ import annotations

import threading

import zenoh

from services.recorder.live.line_inbox import LineInbox, Message
from shared.contract import channels, keys
from tests.support.live_recorder import has_subscribers, wait_until


def blocking_publisher(session: zenoh.Session, key: str) -> zenoh.Publisher:
    publisher = session.declare_publisher(key, congestion_control=zenoh.CongestionControl.BLOCK)
    wait_until(lambda: has_subscribers(publisher), "the inbox")
    return publisher


def take_until(inbox: LineInbox, count: int) -> list[Message]:
    taken: list[Message] = []

    def enough() -> bool:
        taken.extend(inbox.take(0.01))
        return len(taken) >= count

    wait_until(enough, f"{count} messages")
    return taken


def test_every_message_is_kept_in_order_with_its_key_and_receive_time(
    sessions: tuple[zenoh.Session, zenoh.Session],
) -> None:
    served, feeding = sessions
    inbox = LineInbox(served, keys.EVERYTHING)
    try:
        samples = blocking_publisher(feeding, channels.SAMPLES.key("a1"))
        tool = blocking_publisher(feeding, channels.TOOL.key("a2"))
        for i in range(500):
            (tool if i % 100 == 0 else samples).put(str(i).encode())
        taken = take_until(inbox, 500)
    finally:
        inbox.close()
    assert [payload for _, payload, _, _ in taken] == [str(i).encode() for i in range(500)]
    assert {key for key, _, _, _ in taken} == {"boltwatch/a1/samples", "boltwatch/a2/tool"}
    times_ns = [received_ns for _, _, received_ns, _ in taken]
    assert times_ns == sorted(times_ns)
    assert inbox.full_waits == 0


def test_a_full_inbox_holds_the_publisher_back_and_loses_nothing(
    sessions: tuple[zenoh.Session, zenoh.Session],
) -> None:
    served, feeding = sessions
    inbox = LineInbox(served, keys.EVERYTHING, max_pending=10)
    published = threading.Event()
    try:
        samples = blocking_publisher(feeding, channels.SAMPLES.key("a1"))

        def publish() -> None:
            for i in range(300):
                samples.put(str(i).encode())
            published.set()

        publisher_thread = threading.Thread(target=publish, daemon=True)
        publisher_thread.start()
        wait_until(lambda: inbox.full_waits > 0, "the receive thread to wait for room")
        taken = take_until(inbox, 300)
        publisher_thread.join(10.0)
    finally:
        inbox.close()
    assert published.is_set()
    assert [payload for _, payload, _, _ in taken] == [str(i).encode() for i in range(300)]


def test_close_keeps_what_came_before_for_a_last_take(
    sessions: tuple[zenoh.Session, zenoh.Session],
) -> None:
    served, feeding = sessions
    inbox = LineInbox(served, keys.EVERYTHING)
    samples = blocking_publisher(feeding, channels.SAMPLES.key("a1"))
    for i in range(20):
        samples.put(str(i).encode())
    wait_until(lambda: len(inbox._pending) == 20, "20 pending")
    inbox.close()
    inbox.close()  # twice is fine
    wait_until(lambda: not has_subscribers(samples), "the subscriber gone")
    samples.put(b"after close")
    kept = inbox.take(0)
    assert [payload for _, payload, _, _ in kept] == [str(i).encode() for i in range(20)]
    assert inbox.take(0) == []


def test_wake_ends_a_waiting_take_at_once(
    sessions: tuple[zenoh.Session, zenoh.Session],
) -> None:
    served, _ = sessions
    inbox = LineInbox(served, keys.EVERYTHING)
    try:
        waiting = threading.Thread(target=inbox.take, args=(60.0,), daemon=True)
        waiting.start()
        inbox.wake()
        waiting.join(10.0)
        assert not waiting.is_alive()
    finally:
        inbox.close()


def test_close_wakes_a_receive_thread_waiting_for_room_and_counts_its_message(
    sessions: tuple[zenoh.Session, zenoh.Session],
) -> None:
    served, feeding = sessions
    inbox = LineInbox(served, keys.EVERYTHING, max_pending=10)
    samples = blocking_publisher(feeding, channels.SAMPLES.key("a1"))
    publisher_thread = threading.Thread(
        target=lambda: [samples.put(str(i).encode()) for i in range(300)], daemon=True
    )
    publisher_thread.start()
    wait_until(lambda: inbox.full_waits > 0, "the receive thread to wait for room")
    closing = threading.Thread(target=inbox.close, daemon=True)
    closing.start()
    closing.join(10.0)
    assert not closing.is_alive(), "close() hung on the waiting receive thread"
    # The woken receive thread counts its message once it has the lock again.
    wait_until(lambda: inbox.after_close >= 1, "the waiting message counted")
    publisher_thread.join(10.0)
    assert not publisher_thread.is_alive()
    kept = inbox.take(0)
    assert [payload for _, payload, _, _ in kept] == [str(i).encode() for i in range(10)]
