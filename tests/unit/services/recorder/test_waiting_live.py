"""Live messages a spool's hole is not ready for: kept by number, bounded, forgotten once passed."""

from __future__ import annotations

from services.recorder.live.waiting_live import WaitingLive


def test_the_next_expected_is_taken_and_those_below_it_forgotten() -> None:
    waiting: WaitingLive[str] = WaitingLive(max_bytes=100)
    for seq in (5, 3, 4, 9):
        waiting.keep(seq, f"m{seq}", 10)
    waiting.keep(4, "again", 10)  # kept once
    assert waiting.take(3) == "m3"
    assert waiting.take(3) is None
    assert waiting.take(5) == "m5"  # 4 was filed meanwhile (sent again): forgotten
    assert len(waiting) == 1 and waiting.bytes == 10
    assert waiting.take(8) is None and waiting.take(9) == "m9"


def test_past_its_bound_a_message_is_not_kept_and_counted() -> None:
    waiting: WaitingLive[str] = WaitingLive(max_bytes=25)
    waiting.keep(1, "a", 10)
    waiting.keep(2, "b", 10)
    waiting.keep(3, "c", 10)
    assert waiting.full == 1 and len(waiting) == 2


def test_a_runs_records_are_kept_past_the_bound_up_to_their_own() -> None:
    """A summary or result is small and all a full disk leaves of its run: kept past the bytes,
    up to a count of its own."""
    waiting: WaitingLive[str] = WaitingLive(max_bytes=15, max_records=2)
    waiting.keep(1, "batch", 10)
    waiting.keep(2, "batch", 10)  # past the bytes: not kept
    for seq in (3, 4, 5):
        waiting.keep(seq, "summary", 10, record=True)
    assert waiting.full == 2 and waiting.held(1, 10) == [1, 3, 4]
