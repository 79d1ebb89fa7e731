"""Results and curves in any order come out once, in id order, each with its curves."""

from __future__ import annotations

from pathlib import Path

from services.openprotocol.pending_tightenings import (
    KEYS_KEPT,
    MAX_FILL,
    PendingTightenings,
    Take,
)
from services.openprotocol.published_ids import (
    BridgePosition,
    position_path,
    read_position,
    write_position,
)
from tests.support.bridge_harness import curve, figures, key


def test_a_result_waits_for_both_curves_which_may_come_before_or_after_it() -> None:
    pending = PendingTightenings(watermark=4, wait_for_curves=True, trace_timeout_s=3.0)
    assert pending.curve(curve(5, "torque"), 0.0)
    assert pending.result(figures(5), 0.1) is Take.NEW
    assert list(pending.ready(0.2)) == []
    assert pending.curve(curve(5, "angle"), 0.3)
    (tightening,) = pending.ready(0.3)
    assert tightening.complete and tightening.result.tightening_id == 5
    assert pending.watermark == 5
    assert not pending.curve(curve(5, "angle"), 0.4), "a curve after its result went: dropped"


def test_a_result_whose_curves_never_come_goes_without_them_after_the_timeout() -> None:
    pending = PendingTightenings(watermark=0, wait_for_curves=True, trace_timeout_s=3.0)
    pending.result(figures(1), 0.0)
    assert list(pending.ready(2.9)) == []
    (tightening,) = pending.ready(3.0)
    assert tightening.torque is None and tightening.angle is None
    assert pending.curve(curve(9, "torque"), 3.0)
    assert pending.expired_curves(5.9) == 0
    assert pending.expired_curves(6.0) == 1


def test_repeats_are_refused_and_order_is_kept_across_a_gap() -> None:
    pending = PendingTightenings.resume(10, {10: key(10)}, False, 3.0)
    assert pending.result(figures(10), 0.0) is Take.REPEAT, "at the watermark: published"
    assert pending.result(figures(14), 0.0) is Take.NEW
    assert pending.result(figures(14), 0.0) is Take.REPEAT, "pending already"
    assert list(pending.ready(0.0)) == [], "11 to 13 come first"
    assert pending.missing() == [11, 12, 13]
    pending.result(figures(11, filled=True), 0.0)
    pending.give_up(12)  # the controller no longer has it
    pending.result(figures(13, filled=True), 0.0)
    assert [t.result.tightening_id for t in pending.ready(0.0)] == [11, 13, 14]
    assert pending.watermark == 14 and pending.given_up == 1
    assert pending.missing() == []


def test_a_gap_longer_than_the_bound_fetches_only_the_newest() -> None:
    pending = PendingTightenings(watermark=0, wait_for_curves=False, trace_timeout_s=3.0)
    pending.controller_newest(MAX_FILL + 500)
    missing = pending.missing()
    assert missing == list(range(501, MAX_FILL + 501))
    assert pending.watermark == 500 and pending.given_up == 500


def test_a_first_connect_to_ids_counting_from_billions_gives_the_old_ones_up_at_once() -> None:
    """A controller whose ids count from 1.8e9 (Unix-time ids): ids 1..newest - MAX_FILL are
    given up in one step (id by id, the bridge spun for hours and sent no keep-alive)."""
    newest = 1_800_000_000
    pending = PendingTightenings(watermark=0, wait_for_curves=False, trace_timeout_s=3.0)
    pending.give_up(3)  # one given up earlier, below the jump
    pending.controller_newest(newest)
    missing = pending.missing()
    assert missing == list(range(newest - MAX_FILL + 1, newest + 1))
    assert pending.watermark == newest - MAX_FILL
    assert pending.given_up == newest - MAX_FILL


def test_the_position_survives_a_restart_and_a_broken_file_is_the_start(tmp_path: Path) -> None:
    path = tmp_path / "openprotocol_st1.json"
    assert read_position(path) == BridgePosition()
    write_position(path, BridgePosition(41, 0, "ctrl"))
    assert read_position(path) == BridgePosition(41, 0, "ctrl")
    assert [p.name for p in tmp_path.iterdir()] == [path.name], "no temporary left"
    path.write_text('{"watermark": -3}')
    assert read_position(path) == BridgePosition()


def test_a_new_epoch_gives_run_ids_after_every_one_published() -> None:
    position = BridgePosition(watermark=41, run_id_offset=0, controller_name="a")
    epoch = position.new_epoch("b")
    assert epoch == BridgePosition(0, 41, "b")
    assert epoch.run_id(1) == 42
    assert epoch.new_epoch("c").run_id(1) == 42, "an epoch without a tightening moves nothing"


def test_an_id_published_with_another_key_or_none_kept_is_a_conflict_not_a_repeat() -> None:
    """A controller whose ids wrapped or started again sends ids published already."""
    pending = PendingTightenings.resume(10, {9: key(9), 10: key(10)}, False, 3.0)
    assert pending.result(figures(9), 0.0) is Take.REPEAT
    assert pending.result(figures(9, time="2026-11-25:08:00:00"), 0.0) is Take.CONFLICT
    assert pending.result(figures(1), 0.0) is Take.CONFLICT, "older than every key kept"
    assert pending.result(figures(10, filled=True), 0.0) is Take.REPEAT
    upgraded = PendingTightenings.resume(10, {}, False, 3.0)  # a file from before keys
    assert upgraded.result(figures(3), 0.0) is Take.REPEAT, "cannot tell: never twice"
    assert pending.result(figures(11), 0.0) is Take.NEW
    assert pending.result(figures(11, time="2026-11-25:08:00:00"), 0.0) is Take.CONFLICT


def test_published_keys_are_bounded_and_kept_in_id_order() -> None:
    pending = PendingTightenings(watermark=0, wait_for_curves=False, trace_timeout_s=3.0)
    for tightening_id in range(1, KEYS_KEPT + 21):
        assert pending.result(figures(tightening_id), 0.0) is Take.NEW
    assert len(list(pending.ready(0.0))) == KEYS_KEPT + 20
    assert list(pending.published_keys) == list(range(21, KEYS_KEPT + 21))


def test_a_flood_of_results_is_never_given_up_however_many_came() -> None:
    """3000 results pushed as fast as the link takes them, their curves still to come:
    every one is here, none is fetched or given up, all go out once, in order."""
    pending = PendingTightenings(watermark=0, wait_for_curves=True, trace_timeout_s=3.0)
    for tightening_id in range(1, 3001):
        assert pending.result(figures(tightening_id), 0.0) is Take.NEW
        assert pending.missing() == []
    assert pending.given_up == 0
    assert [t.result.tightening_id for t in pending.ready(3.0)] == list(range(1, 3001))


def test_a_gap_beyond_the_bound_never_passes_a_result_that_is_here() -> None:
    pending = PendingTightenings(watermark=0, wait_for_curves=False, trace_timeout_s=3.0)
    pending.result(figures(5), 0.0)  # here, far below the newest
    pending.controller_newest(MAX_FILL + 500)
    assert pending.missing() == list(range(501, MAX_FILL + 501))
    assert pending.watermark == 4, "ids 1 to 4 given up, 5 is here"
    assert [t.result.tightening_id for t in pending.ready(0.0)] == [5]
    assert pending.watermark == 500
    assert pending.given_up == 499


def test_drain_hands_out_what_is_pending_in_id_order_and_gives_the_gaps_up() -> None:
    pending = PendingTightenings(watermark=2, wait_for_curves=True, trace_timeout_s=3.0)
    for tightening_id in (7, 4, 5):
        pending.result(figures(tightening_id), 0.0)
    assert [t.result.tightening_id for t in pending.drain()] == [4, 5, 7]
    assert pending.watermark == 7 and pending.given_up == 2  # 3 and 6
    assert pending.waiting_results() == 0


def test_a_live_result_of_one_fetched_by_id_is_no_repeat_and_takes_its_place() -> None:
    """A tightening made while the bridge caught up: fetched by id (0065, no limits) and
    pushed live (0061) too."""
    pending = PendingTightenings(watermark=0, wait_for_curves=False, trace_timeout_s=3.0)
    assert pending.result(figures(2, filled=True), 0.0) is Take.NEW
    assert pending.result(figures(2), 0.0) is Take.FETCHED
    assert pending.result(figures(2), 0.0) is Take.REPEAT, "the live one, sent again"
    assert pending.result(figures(1, filled=True), 0.0) is Take.NEW
    first, second = pending.ready(0.0)
    assert first.result.filled and not second.result.filled
    assert pending.result(figures(1), 0.0) is Take.FETCHED, "published from its 0065"


def test_an_epoch_that_starts_after_an_id_goes_on_with_the_next_run_id_and_is_kept(
    tmp_path: Path,
) -> None:
    """The ids jumped to 9999999999 after 3117, then went back to 3118: run ids go on
    one by one (the offset may be negative), and the keys of the epochs before are kept
    in the file."""
    position = BridgePosition(3117, 0, "a", {3116: key(3116), 3117: key(3117)})
    jumped = position.new_epoch("a", start_after=9_999_999_998)
    assert jumped.run_id(9_999_999_999) == 3118
    assert jumped.previous_keys == {3116: key(3116), 3117: key(3117)}
    published = BridgePosition(
        9_999_999_999, jumped.run_id_offset, "a", {9_999_999_999: key(9)}, "",
        jumped.previous_keys,
    )  # fmt: skip
    back = published.new_epoch("a", start_after=3117)
    assert back.run_id(3118) == 3119
    assert list(back.previous_keys) == [3116, 3117, 9_999_999_999]
    path = position_path(tmp_path, "op1")
    write_position(path, jumped)
    assert read_position(path) == jumped
