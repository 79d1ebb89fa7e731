"""The bridge against a hostile controller: every message it cannot use costs that message.

Malformed and extreme messages as a faulty or misconfigured controller sends
them, from :class:`~tests.support.openprotocol_controller.SpecController`
(written from the specification, not from our codec): every field of 0061
and 0900 empty, too long, not a number, out of range; ids that wrap, repeat,
jump back; a flood; time stamps no clock holds. In every case the bridge lives
on, no tightening is published twice, and what it refused is counted and
logged once per kind (rate-limited), never once per message.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import zenoh

from services.opcua.result_values import EVALUATION_NOT_OK, result_values
from shared.results import ResultsQuery, ResultsStore, StoredResult, StoreTarget
from shared.results.results_table import row
from tests.support.bridge_harness import RunningBridge, bridge_station_file
from tests.support.listener import Listener
from tests.support.live_recorder import wait_until
from tests.support.openprotocol_controller import SpecController
from tests.support.openprotocol_results import last_result_fields

#: 0061 revision 2 parameters that are text: any characters are a value
TEXT_FIELDS = {3, 4, 44}
#: 0061 revision 2 parameters that are a date and time
TIME_FIELDS = {45, 46}
#: the most log lines a hostile burst may cost (one per kind, then every 10 s)
LOG_LINES_AT_MOST = 30


@pytest.fixture
def controller() -> Iterator[SpecController]:
    with SpecController(results_kept=5000) as served:
        yield served


@pytest.fixture
def bridge(
    tmp_path: Path, controller: SpecController, sessions: tuple[zenoh.Session, zenoh.Session]
) -> Iterator[tuple[RunningBridge, Listener]]:
    served, feeding = sessions
    heard = Listener(served, samples_from_batches=True)
    station_file = bridge_station_file(tmp_path, controller.port, "tcp/127.0.0.1:1")
    running = RunningBridge(station_file, feeding)
    assert controller.wait_subscribed(10.0, mids=(61, 900, 71))
    yield running, heard
    assert running.thread.is_alive(), "the bridge died"
    running.finish()
    heard.close()


def result_ids(heard: Listener) -> list[int]:
    return [result.tightening_id for result in heard.of("results")]


def hostile_values(text: str, pid: int) -> dict[str, str]:
    """What a faulty controller writes in a field whose good value is ``text``."""
    width = len(text)
    values = {"empty": "", "too long": text + "99", "not a number": ("12a456" * 4)[:width]}
    if pid in TIME_FIELDS:
        values["out of range"] = "2026-13-45:25:61:61"
    elif width == 1:
        values["out of range"] = "7"
    elif pid not in TEXT_FIELDS:
        values["out of range"] = "-" + "1" * (width - 1)
    return values


def bridge_log_lines(caplog: pytest.LogCaptureFixture) -> list[str]:
    return [
        record.getMessage()
        for record in caplog.records
        if record.name.startswith("services.openprotocol") and record.levelno >= logging.INFO
    ]


def test_every_field_of_0061_bad_in_every_way_costs_that_message_never_a_tightening(
    controller: SpecController,
    bridge: tuple[RunningBridge, Listener],
    caplog: pytest.LogCaptureFixture,
) -> None:
    """Each bad 0061 is of a tightening the controller keeps: refused (counted), it comes
    back by 0064 with the controller's values; a text field of any characters is a value."""
    caplog.set_level(logging.INFO)
    running, heard = bridge
    fields = last_result_fields(controller.results[controller.tighten()], 2, controller.identity)
    wait_until(lambda: result_ids(heard) == [1], "the first tightening")
    sent = [1]
    refusals_due = 0
    for pid, text in fields:
        for kind, value in hostile_values(text, pid).items():
            tightening_id = controller.tighten(push=False, curves=False)
            controller.send_raw(controller.result_wire(tightening_id, 2, {pid: value}))
            sent.append(tightening_id)
            refusals_due += kind in ("empty", "too long")
            wait_until(lambda: len(result_ids(heard)) >= len(sent), f"{pid} {kind}")
    final = controller.tighten()
    sent.append(final)
    wait_until(lambda: len(result_ids(heard)) >= len(sent), "the good one after them")
    time.sleep(0.5)  # nothing more may come
    assert result_ids(heard) == sent, "each tightening once, in order"
    for result in heard.of("results"):
        said = controller.results[result.tightening_id]
        assert result.final_torque_nm.value == pytest.approx(said.torque_nm) or (
            result.tightening_id != final and result.final_torque_nm.value is not None
        )
    counts = running.counts
    assert counts.bad_messages + counts.refused_values >= refusals_due
    assert counts.repeated_results == 0 and counts.epochs == 0
    assert len(bridge_log_lines(caplog)) <= LOG_LINES_AT_MOST, bridge_log_lines(caplog)


@pytest.mark.parametrize(
    "overrides",
    [
        {"resolution": False},
        {"time_value": "1e300"},
        {"time_value": "1e-300"},
        {"time_value": "abc"},
        {"time_value": "-1"},
        {"coefficient": "0"},
        {"coefficient": "abc"},
        {"coefficient": "1e300"},
        {"declared_samples": 5},
        {"result_data_id": "12a4567890"},
    ],
    ids=lambda overrides: ",".join(f"{k}={v}" for k, v in overrides.items()),
)
def test_a_bad_0900_costs_its_curve_never_the_bridge_or_the_result(
    controller: SpecController, bridge: tuple[RunningBridge, Listener], overrides: dict[str, Any]
) -> None:
    """Before: a 0900 without resolution fields or with a time step of 1e300 s stopped the
    bridge (exit 1); one of 1e-300 s was published and missing from the wear ledger."""
    running, heard = bridge
    tightening_id = controller.tighten(push=False)
    controller.send_raw(
        controller.trace_wire(tightening_id, 2, **overrides)
        + controller.trace_wire(tightening_id, 1)
        + controller.result_wire(tightening_id, 2)
    )
    wait_until(lambda: result_ids(heard) == [tightening_id], "the result")
    counts = running.counts
    assert counts.traces <= 1, "the bad torque curve is not published"
    assert counts.traces_refused + counts.refused_values + counts.bad_messages >= 1
    good = controller.tighten()
    wait_until(lambda: result_ids(heard) == [tightening_id, good], "the next tightening")
    assert counts.traces == 1 + 2, "the next one's curves"


def test_ids_that_wrap_after_9999999999_go_on_as_new_runs_each_once(
    controller: SpecController, bridge: tuple[RunningBridge, Listener]
) -> None:
    """Before: the ids after the wrap were withheld while the link stayed up, then 997 old
    tightenings were published again under new run ids (counted twice by the ledger)."""
    running, heard = bridge
    controller.count_from(9_999_999_997)
    made = [controller.tighten() for _ in range(5)]
    assert made == [9_999_999_997, 9_999_999_998, 9_999_999_999, 1, 2]
    # the first connect to ids near the wrap: the 1000 ids before the first are asked for
    wait_until(lambda: len(result_ids(heard)) == 5, "five results", timeout_s=60.0)
    time.sleep(0.5)
    assert result_ids(heard) == made
    run_ids = [result.run_id for result in heard.of("results")]
    assert run_ids == sorted(set(run_ids)), "run ids go on"
    assert running.counts.epochs == 1


def test_a_repeat_is_counted_and_an_old_id_with_other_values_is_a_new_run(
    controller: SpecController, bridge: tuple[RunningBridge, Listener]
) -> None:
    running, heard = bridge
    for _ in range(3):
        controller.tighten()
    wait_until(lambda: len(result_ids(heard)) == 3, "three results")
    controller.send_raw(controller.result_wire(2, 2))  # sent again, as it was
    wait_until(lambda: running.counts.repeated_results == 1, "the repeat counted")
    later = controller.results[2].time_s + 60.0
    stamp = time.strftime("%Y-%m-%d:%H:%M:%S", time.localtime(later))
    controller.send_raw(controller.result_wire(2, 2, {45: stamp}))  # jumps back: another one
    wait_until(lambda: len(result_ids(heard)) == 4, "the jump back published once")
    time.sleep(0.5)
    assert result_ids(heard) == [1, 2, 3, 2], "1 and 3 of the epoch before: not again"
    run_ids = [result.run_id for result in heard.of("results")]
    assert run_ids == [1, 2, 3, 4], "the new epoch's run ids go on after the last one"
    assert running.counts.epochs == 1


def test_a_flood_of_3000_results_publishes_each_once_and_logs_a_few_lines(
    controller: SpecController,
    bridge: tuple[RunningBridge, Listener],
    caplog: pytest.LogCaptureFixture,
) -> None:
    """Before: 1000 of 3000 were published ("more than 1000 results back: given up") and
    29 600 lines "tightening 117 again" were logged."""
    caplog.set_level(logging.INFO)
    running, heard = bridge
    made = [controller.tighten(push=False, curves=False) for _ in range(3000)]
    controller.send_raw(b"".join(controller.result_wire(i, 2) for i in made))
    wait_until(lambda: len(result_ids(heard)) >= 3000, "3000 results", timeout_s=120.0)
    time.sleep(0.5)
    assert result_ids(heard) == made
    assert running.counts.results_given_up == 0 and running.counts.repeated_results == 0
    assert len(bridge_log_lines(caplog)) <= LOG_LINES_AT_MOST


@pytest.mark.parametrize("stamp", ["9999-12-31:23:59:59", "1900-01-01:00:00:00"])
def test_a_time_stamp_no_clock_holds_is_replaced_by_the_time_received(
    controller: SpecController, bridge: tuple[RunningBridge, Listener], stamp: str
) -> None:
    """Before: published, but such results never reached the wear ledger."""
    running, heard = bridge
    tightening_id = controller.tighten(push=False, curves=False)
    before_ns = time.time_ns()
    controller.send_raw(controller.result_wire(tightening_id, 2, {45: stamp}))
    wait_until(lambda: result_ids(heard) == [tightening_id], "the result")
    (result,) = heard.of("results")
    assert before_ns - 5_000_000_000 <= result.time_ns <= time.time_ns()
    assert running.counts.clock_refused == 1
    (summary,) = heard.of("runs") or [None]
    assert summary is not None and summary.ended_ns <= time.time_ns()


def test_a_controller_that_says_ok_outside_its_own_window_gives_a_nok_saying_so(
    controller: SpecController, bridge: tuple[RunningBridge, Listener], tmp_path: Path
) -> None:
    """Before: 9999.99 Nm in a 100-250 Nm window was published OK with the NOK reason
    "torque high" beside it: OK in the results store, ``results``, ``report`` and OPC UA."""
    _, heard = bridge
    tightening_id = controller.tighten(
        torque_nm=9999.99, ok=True, torque_min_nm=100.0, torque_max_nm=250.0,
        torque_target_nm=200.0,
    )  # fmt: skip
    wait_until(lambda: result_ids(heard) == [tightening_id], "the result")
    (result,) = heard.of("results")
    (said,) = heard.of("controller")
    assert said.result == "OK", "the controller's own message stays what it said"
    assert result.result == "NOK"
    assert result.final_torque_nm.status == "high"
    assert result.nok_reasons == (
        "the controller said OK, the windows NOK; torque high: 9999.99 Nm, window 100 to 250 Nm"
    )
    stored = StoredResult(result)
    with ResultsStore(StoreTarget(sqlite_path=tmp_path / "results.sqlite")) as store:
        store.add([stored])
        (back,) = store.find(ResultsQuery())
    assert back.result.result == "NOK" and back.result.nok_reasons == result.nok_reasons
    shown = row(back)
    assert shown[8] == "NOK" and shown[14] == result.nok_reasons  # `boltwatch results`
    meta = result_values(back.result)["ResultMetaData"]
    assert meta["ResultEvaluation"] == EVALUATION_NOT_OK
    assert meta["ResultEvaluationDetails"] == result.nok_reasons


def test_an_id_that_jumps_to_9999999999_and_back_publishes_each_tightening_once(
    controller: SpecController, bridge: tuple[RunningBridge, Listener]
) -> None:
    """Ids 1-60, then 9999999999, then 61 on (the controller's counter jumped and came
    back), with a link drop after. Before: the bridge asked 0064 a thousand times,
    published none of 61-65 while the link stayed up, and after the drop published them
    and 58 earlier tightenings again under new run ids (the wear ledger counted them
    twice)."""
    running, heard = bridge
    made = [controller.tighten(curves=False) for _ in range(60)]
    wait_until(lambda: len(result_ids(heard)) == 60, "the first 60")
    controller.count_from(9_999_999_999)
    made.append(controller.tighten(curves=False))
    controller.count_from(61)
    made += [controller.tighten(curves=False) for _ in range(5)]
    wait_until(lambda: result_ids(heard) == made, "the jump and 61-65", timeout_s=20.0)
    controller.drop()
    assert controller.wait_for(lambda: 61 not in controller.subscriptions, 5.0)
    assert controller.wait_subscribed(10.0, mids=(61,)), "the bridge is back"
    made += [controller.tighten(curves=False) for _ in range(2)]
    wait_until(lambda: len(result_ids(heard)) >= len(made), "66 and 67 after the drop")
    time.sleep(0.5)  # nothing more may come
    assert result_ids(heard) == made, "each tightening once, in the order made"
    run_ids = [result.run_id for result in heard.of("results")]
    assert run_ids == sorted(set(run_ids)), "run ids go on, never one twice"
    asked = [wanted for wanted, _ in controller.old_result_requests if wanted != 0]
    assert len(asked) <= 5, f"0064 asked for {len(asked)} ids"
    assert running.counts.results_given_up == 0


def test_ids_back_below_the_watermark_while_the_link_was_down_go_on_after_the_kept_ones(
    controller: SpecController, bridge: tuple[RunningBridge, Listener]
) -> None:
    """Ids 1-150, then 9999999999; the link drops; the controller goes on at 151 while
    the bridge is away. Its newest (153) is below the watermark: a new epoch, which starts
    after 150 (the controller still keeps 150 as published), not at 1. Before: ids 1-50
    (older than the keys kept) were published again under new run ids."""
    running, heard = bridge
    assert running.counts.epochs == 0
    made = [controller.tighten(push=False, curves=False) for _ in range(150)]
    controller.send_raw(b"".join(controller.result_wire(i, 2) for i in made))
    wait_until(lambda: len(result_ids(heard)) == 150, "the first 150", timeout_s=30.0)
    controller.count_from(9_999_999_999)
    made.append(controller.tighten(curves=False))
    wait_until(lambda: len(result_ids(heard)) == 151, "the jump")
    controller.drop()
    controller.count_from(151)
    made += [controller.tighten(curves=False) for _ in range(3)]
    wait_until(lambda: len(result_ids(heard)) >= len(made), "151-153 after the drop")
    time.sleep(0.5)  # nothing more may come
    assert result_ids(heard) == made, "each tightening once"
    run_ids = [result.run_id for result in heard.of("results")]
    assert run_ids == list(range(1, 155)), "run ids go on one by one"
    asked = [wanted for wanted, _ in controller.old_result_requests if wanted != 0]
    assert len(asked) <= 10, f"0064 asked for {len(asked)} ids"
