"""The bridge against a real TCP controller, publishing on real zenoh: every tightening once."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
import zenoh

from services.openprotocol.published_ids import read_position
from tests.support.bridge_harness import RunningBridge, bridge_station_file
from tests.support.listener import Listener
from tests.support.live_recorder import wait_until
from tests.support.tcp_controller import SAMPLES, TcpController


@pytest.fixture
def controller() -> Iterator[TcpController]:
    served = TcpController()
    yield served
    served.close()


def ids_of(heard: Listener, topic: str) -> list[int]:
    return [message.run_id for message in heard.of(topic)]


def test_live_results_with_their_curves_become_runs_once_each(
    tmp_path: Path, controller: TcpController, sessions: tuple[zenoh.Session, zenoh.Session]
) -> None:
    served, feeding = sessions
    heard = Listener(served, samples_from_batches=True)
    endpoint = "tcp/127.0.0.1:1"  # the sessions fixture's peers carry the messages
    station_file = bridge_station_file(tmp_path, controller.port, endpoint)
    bridge = RunningBridge(station_file, feeding)
    try:
        wait_until(lambda: controller.traces_subscribed, "the subscriptions")
        for _ in range(3):
            controller.tighten()
        wait_until(lambda: len(heard.of("runs")) == 3, "three runs")
        assert ids_of(heard, "runs") == [1, 2, 3]
        assert ids_of(heard, "results") == [1, 2, 3]
        assert [r.source for r in heard.of("results")] == ["controller"] * 3
        assert len(heard.of("samples")) == 3 * SAMPLES
        assert [s.state for s in heard.of("tool")] == ["running", "done"] * 3
        assert len(heard.of("controller")) == 3
        # tool data at the connect, then again after each tightening (its counters moved)
        wait_until(lambda: len(heard.of("tool_data")) >= 2, "tool data asked again")
        tool_data = heard.of("tool_data")
        assert {(tool.tool_serial, tool.tool_id) for tool in tool_data} == {("SIM-3", 7)}
        assert controller.acks == 3
        assert bridge.counts.traces == 6 and bridge.counts.results_without_traces == 0
        assert bridge.counts.controller_errors == 0
        assert all(summary.events > 0 for summary in heard.of("runs"))
    finally:
        bridge.finish()
        heard.close()
    # the test controller reads the 0003 on its own thread, after the bridge has sent it
    wait_until(lambda: controller.stops == 1, "a clean 0003 on shutdown")
    assert controller.stops == 1
    assert read_position(bridge.position_file).watermark == 3


def test_results_made_while_the_link_was_down_are_fetched_by_id_once(
    tmp_path: Path, controller: TcpController, sessions: tuple[zenoh.Session, zenoh.Session]
) -> None:
    served, feeding = sessions
    heard = Listener(served, samples_from_batches=True)
    station_file = bridge_station_file(tmp_path, controller.port, "tcp/127.0.0.1:1")
    bridge = RunningBridge(station_file, feeding)
    try:
        wait_until(lambda: controller.traces_subscribed, "the subscriptions")
        controller.tighten()
        wait_until(lambda: len(heard.of("runs")) == 1, "the first run")
        bridge.finish()  # the bridge is gone; the controller keeps tightening
        for _ in range(3):
            controller.tighten(push=False)
        bridge = RunningBridge(station_file, feeding)
        wait_until(lambda: len(heard.of("runs")) == 4, "the runs made meanwhile")
        controller.tighten()
        wait_until(lambda: len(heard.of("runs")) == 5, "the next live run")
        assert ids_of(heard, "runs") == [1, 2, 3, 4, 5]
        assert bridge.counts.results_filled == 3
        assert bridge.counts.repeated_results == 0
    finally:
        bridge.finish()
        heard.close()


def test_revisions_fall_back_on_error_97(
    tmp_path: Path, sessions: tuple[zenoh.Session, zenoh.Session]
) -> None:
    controller = TcpController(start_revision=1, result_revision=1, mirror=False)
    served, feeding = sessions
    heard = Listener(served, samples_from_batches=True)
    station_file = bridge_station_file(tmp_path, controller.port, "tcp/127.0.0.1:1")
    bridge = RunningBridge(station_file, feeding)
    try:
        wait_until(lambda: bridge.counts.result_revision == 1, "the rev 1 subscription")
        controller.tighten()
        wait_until(lambda: len(heard.of("runs")) == 1, "a run from a rev 1 result")
        # 0001 rev 3, 2 and 0060 rev 2 refused with error 97: a fall-back, not a fault
        assert bridge.counts.controller_errors == 0
        assert bridge.counts.last_error is None
        assert heard.of("results")[0].final_torque_nm.min == 180.0
    finally:
        bridge.finish()
        heard.close()
        controller.close()


def test_garbage_wrong_lengths_and_a_value_out_of_range_are_counted_and_nothing_is_lost(
    tmp_path: Path, controller: TcpController, sessions: tuple[zenoh.Session, zenoh.Session]
) -> None:
    served, feeding = sessions
    heard = Listener(served, samples_from_batches=True)
    station_file = bridge_station_file(tmp_path, controller.port, "tcp/127.0.0.1:1")
    bridge = RunningBridge(station_file, feeding)
    try:
        wait_until(lambda: controller.traces_subscribed, "the subscriptions")
        controller.tighten()
        controller.send_raw(b"0030006100          short\x00")  # 0061 whose data is cut
        controller.send_raw(b"\x01\x02garbage bytes\xff")
        good = controller.result_bytes(controller.tighten(push=False))
        # its time stamp a date that does not exist: a field out of range
        controller.send_raw(good.replace(b"2026-11-24", b"2026-13-45", 1))
        controller.tighten()  # id 3: the refused 2 is fetched by id first
        wait_until(lambda: len(heard.of("runs")) == 3, "every run, the refused one fetched")
        assert ids_of(heard, "runs") == [1, 2, 3]
        counts = bridge.counts
        assert counts.garbage_bytes > 0
        assert counts.bad_messages >= 1
        assert counts.refused_values == 1
        assert counts.results_filled == 1 and counts.repeated_results == 0
        assert controller.connections == 1, "the link went on"
        stats = counts.stats()
        assert stats.refused_values == 1 and stats.last_error is not None
    finally:
        bridge.finish()
        heard.close()


def test_a_link_dropped_mid_trace_loses_no_result(
    tmp_path: Path, controller: TcpController, sessions: tuple[zenoh.Session, zenoh.Session]
) -> None:
    served, feeding = sessions
    heard = Listener(served, samples_from_batches=True)
    station_file = bridge_station_file(tmp_path, controller.port, "tcp/127.0.0.1:1")
    bridge = RunningBridge(station_file, feeding, trace_timeout_s=0.5)
    try:
        wait_until(lambda: controller.traces_subscribed, "the trace subscription")
        controller.tighten(drop_after_first_curve=True)  # its angle curve, then the cut
        wait_until(lambda: bridge.counts.link_drops == 1, "the drop")
        wait_until(lambda: len(heard.of("runs")) == 1, "the run, fetched after the reconnect")
        assert bridge.counts.results_filled == 1
        assert bridge.counts.traces == 1, "the curve that came before the cut is the run's"
        assert len(heard.of("samples")) == SAMPLES
        controller.tighten()
        wait_until(lambda: len(heard.of("runs")) == 2, "the next run")
        assert ids_of(heard, "runs") == [1, 2]
    finally:
        bridge.finish()
        heard.close()


def test_a_controller_whose_ids_start_again_gets_run_ids_after_the_last(
    tmp_path: Path, sessions: tuple[zenoh.Session, zenoh.Session]
) -> None:
    served, feeding = sessions
    heard = Listener(served, samples_from_batches=True)
    first = TcpController()
    station_file = bridge_station_file(tmp_path, first.port, "tcp/127.0.0.1:1")
    bridge = RunningBridge(station_file, feeding)
    try:
        wait_until(lambda: first.traces_subscribed, "the subscriptions")
        for _ in range(3):
            first.tighten()
        wait_until(lambda: len(heard.of("runs")) == 3, "three runs")
    finally:
        bridge.finish()
        first.close()
    # reset: its ids start at 1 again, its clock goes on
    replaced = TcpController(port=first.port, timestamp="2026-11-24:11:00:00")
    replaced.tighten(push=False)
    bridge = RunningBridge(station_file, feeding)
    try:
        wait_until(lambda: len(heard.of("runs")) == 4, "the reset controller's run")
        replaced.tighten()
        wait_until(lambda: len(heard.of("runs")) == 5, "its next run")
        assert ids_of(heard, "runs") == [1, 2, 3, 4, 5]
        assert [r.tightening_id for r in heard.of("results")] == [1, 2, 3, 1, 2]
    finally:
        bridge.finish()
        heard.close()
        replaced.close()
