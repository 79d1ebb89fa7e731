"""The bridge, with its default settings, against a controller we did not write from our codec.

:class:`~tests.support.openprotocol_controller.SpecController` was written from
the specification's text (R2.8.0, checked against R2.16.0) and public
implementations, never from ``shared.openprotocol``: it names the MID
subscribed for in the 0005 of a 0008 (or 0008 itself), cuts its writes any
way a TCP stream can be cut, restarts with ids from 1, writes 0900 samples in
either byte order and scaling. The bridge runs in a thread on real zenoh
(:mod:`tests.support.bridge_harness`).
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import zenoh

from tests.support.bridge_harness import (
    RunningBridge,
    bridge_station_file,
    controller_station_file,
)
from tests.support.listener import Listener
from tests.support.live_recorder import wait_until
from tests.support.openprotocol_controller import SpecController
from tests.support.openprotocol_core import AcceptNames
from tests.support.openprotocol_link import WriteMode
from tests.support.openprotocol_traces import ByteOrder, Scaling

TIGHTENINGS = 10


class Line:
    """The bridge of a station file for ``controller``, and what it published."""

    def __init__(
        self, tmp_path: Path, controller: SpecController, sessions: tuple[Any, Any], **section: Any
    ) -> None:
        served, feeding = sessions
        self.heard = Listener(served, samples_from_batches=True)
        self.station_file = bridge_station_file(
            tmp_path, controller.port, "tcp/127.0.0.1:1", **section
        )
        self._feeding = feeding
        self.bridge = RunningBridge(self.station_file, feeding)

    def restart_bridge(self) -> None:
        self.bridge.finish()
        self.bridge = RunningBridge(self.station_file, self._feeding)

    def results(self) -> list[Any]:
        return self.heard.of("results")

    def wait_results(self, count: int, what: str) -> list[Any]:
        wait_until(lambda: len(self.results()) >= count, what, timeout_s=30.0)
        return self.results()

    def close(self) -> None:
        self.bridge.finish()
        self.heard.close()


@pytest.fixture
def line_of(tmp_path: Path, sessions: tuple[zenoh.Session, zenoh.Session]) -> Iterator[Any]:
    made: list[Line] = []

    def make(controller: SpecController, **section: Any) -> Line:
        made.append(Line(tmp_path, controller, sessions, **section))
        return made[-1]

    yield make
    for line in made:
        line.close()


def tighten_all(
    controller: SpecController, count: int = TIGHTENINGS, part: str = "VIN", **kwargs: Any
) -> list[int]:
    """``count`` tightenings of different torques and angles, batch counted, each its part."""
    return [
        controller.tighten(
            torque_nm=24.0 + 0.25 * i,
            angle_deg=150.0 + 7.0 * i,
            batch_size=count,
            batch_counter=i + 1,
            vin=f"{part}{i:04d}",
            **kwargs,
        )
        for i in range(count)
    ]


def assert_as_the_controller_said(results: list[Any], controller: SpecController) -> None:
    """Each result once, in id order, with the controller's own values."""
    ids = [result.tightening_id for result in results]
    assert ids == sorted(set(ids)), f"each once, in order: {ids}"
    for result in results:
        said = controller.results[result.tightening_id]
        assert result.final_torque_nm.value == pytest.approx(said.torque_nm)
        assert result.final_angle_deg.value == pytest.approx(round(said.angle_deg))
        assert result.batch_counter == said.batch_counter
        assert result.part_id == said.vin
        assert result.result == ("OK" if said.ok else "NOK")


@pytest.mark.parametrize(
    ("accept_names", "write_mode"),
    [
        ("subscribed", "whole"),
        ("subscribed", "coalesced"),
        ("subscribing", "bytewise"),
        ("subscribed", "random"),
    ],
)
def test_ten_tightenings_are_recorded_once_with_the_controllers_values_and_curves(
    line_of: Any, accept_names: AcceptNames, write_mode: WriteMode
) -> None:
    """Before: a 0005 naming 0900 was never taken for the answer to 0008, the link dropped
    and started again for ever, and no tightening was published; messages that shared a
    TCP read with an answer were thrown away."""
    with SpecController(accept_names=accept_names, write_mode=write_mode) as controller:
        line = line_of(controller)
        assert controller.wait_subscribed(10.0, mids=(61, 900, 71))
        tighten_all(controller)
        results = line.wait_results(TIGHTENINGS, "ten results")
        assert_as_the_controller_said(results, controller)
        assert [r.tightening_id for r in results] == list(range(1, TIGHTENINGS + 1))
        wait_until(lambda: len(line.heard.of("runs")) == TIGHTENINGS, "ten runs")
        samples = line.heard.of("samples")
        expected = sum(len(controller.curves[i].torque_nm) for i in range(1, TIGHTENINGS + 1))
        assert len(samples) == expected, "every curve's samples"
        by_run: dict[int, float] = {}
        for sample in samples:
            by_run[sample.run_id] = max(by_run.get(sample.run_id, 0.0), sample.torque_nm)
        for run_id, peak in by_run.items():
            assert peak == pytest.approx(controller.results[run_id].torque_nm, abs=0.011)
        counts = line.bridge.counts
        assert counts.connects == 1 and counts.link_drops == 0
        assert counts.traces == 2 * TIGHTENINGS and counts.traces_refused == 0
        assert counts.controller_errors == 0 and counts.repeated_results == 0
        assert counts.trace_reading == "big-endian, scaling as declared"
        # the bridge acknowledges a result after publishing it: the last may be on its way
        wait_until(
            lambda: set(controller.delivered_ids) >= set(range(1, TIGHTENINGS + 1)),
            "every result acknowledged to the controller",
        )
        assert controller.tool_data_revisions[0] == 5, "0040 at the highest revision known"
        tool = line.heard.of("tool_data")[0]
        assert tool.tool_model == controller.identity.tool_model
        assert tool.tightenings_since_service is not None and tool.tool_type == "4"


def test_results_fetched_by_id_after_a_restart_keep_their_values(line_of: Any) -> None:
    """Before: final torque, final angle and batch counter were null, and 0064 was always
    asked at revision 1."""
    with SpecController() as controller:
        line = line_of(controller)
        assert controller.wait_subscribed(10.0, mids=(61, 900))
        tighten_all(controller, 3)
        line.wait_results(3, "three live results")
        line.bridge.finish()
        tighten_all(controller, 4, push=False)
        line.restart_bridge()
        results = line.wait_results(7, "the four made while the bridge was away")
        assert_as_the_controller_said(results, controller)
        assert line.bridge.counts.results_filled == 4
        fetched = [request for request in controller.old_result_requests if request[0] > 0]
        assert {revision for _, revision in fetched} == {2}, fetched


@pytest.mark.parametrize(
    ("made_before", "made_after"),
    [(0, 3), (5, 3), (15, 3)],
    ids=["no-result-yet", "below-the-old-last-id", "past-the-old-last-id"],
)
def test_a_controller_restarted_with_ids_from_1_loses_nothing(
    line_of: Any, made_before: int, made_after: int
) -> None:
    """Ten tightenings published; the controller is reset (ids from 1, results gone) and
    makes ``made_before`` while the link is down, then ``made_after`` live. Before: with
    no result yet its ids 1-4 were taken for repeats; past the old last id its new ids
    1..10 were never fetched."""
    with SpecController() as controller:
        line = line_of(controller)
        assert controller.wait_subscribed(10.0, mids=(61, 900))
        tighten_all(controller)
        line.wait_results(TIGHTENINGS, "the first epoch")
        first_keys = {r.tightening_id: r.time_ns for r in line.results()}
        line.bridge.finish()
        controller.restart(next_id=1)
        # new parts after the reset (the same second, the same figures: only the part differs)
        tighten_all(controller, made_before, part="NEW", push=False)
        line.restart_bridge()
        assert controller.wait_subscribed(10.0, mids=(61, 900))
        tighten_all(controller, made_after, part="NXT")
        total = TIGHTENINGS + made_before + made_after
        results = line.wait_results(total, "every tightening of both epochs")
        assert len(results) == total
        run_ids = [r.run_id for r in results]
        assert run_ids == list(range(1, total + 1)), "run ids go on after the last one"
        second = results[TIGHTENINGS:]
        assert [r.tightening_id for r in second] == list(range(1, made_before + made_after + 1))
        assert_as_the_controller_said(second, controller)
        assert {r.tightening_id: r.time_ns for r in results[:TIGHTENINGS]} == first_keys
        assert line.bridge.counts.epochs == 1


@pytest.mark.parametrize(
    ("byte_order", "scaling"),
    [("little", "coefficient"), ("big", "divisor"), ("little", "divisor")],
)
def test_curves_in_either_byte_order_and_scaling_are_read_right(
    line_of: Any, byte_order: ByteOrder, scaling: Scaling
) -> None:
    """Before: little-endian samples were read big-endian, a 25 Nm tightening peaked at
    322 Nm, nothing was counted, and the wear ledger took thousands of times the intensity."""
    with SpecController(trace_byte_order=byte_order, scaling=scaling) as controller:
        line = line_of(controller)
        assert controller.wait_subscribed(10.0, mids=(61, 900))
        tighten_all(controller, 3)
        line.wait_results(3, "three results")
        wait_until(lambda: len(line.heard.of("runs")) == 3, "three runs")
        peaks: dict[int, float] = {}
        for sample in line.heard.of("samples"):
            peaks[sample.run_id] = max(peaks.get(sample.run_id, -1e9), sample.torque_nm)
        assert peaks == pytest.approx(
            {i: controller.results[i].torque_nm for i in (1, 2, 3)}, abs=0.011
        )
        counts = line.bridge.counts
        assert counts.traces == 6 and counts.traces_refused == 0
        assert counts.trace_reading is not None and counts.trace_reading.startswith(byte_order)


def test_the_alarm_active_on_the_controller_is_in_the_bridges_counters(line_of: Any) -> None:
    """Before: ``status`` said 'none active' unless it heard the alarm in its window."""
    with SpecController() as controller:
        controller.raise_alarm("E404", "tool overheated")
        line = line_of(controller)
        assert controller.wait_subscribed(10.0, mids=(61, 71))
        wait_until(lambda: line.bridge.counts.active_alarm is not None, "the 0076 at subscribe")
        alarm = line.bridge.counts.active_alarm
        assert alarm is not None and (alarm.error_code, alarm.active) == ("E404", True)
        controller.clear_alarm()
        wait_until(lambda: line.bridge.counts.active_alarm is None, "cleared by 0074")
        controller.raise_alarm("E501", "low battery")
        wait_until(lambda: line.bridge.counts.active_alarm is not None, "a 0071")
        assert line.bridge.counts.stats().active_alarm is not None


def test_a_controller_station_judges_with_its_psets_windows_else_the_controllers(
    tmp_path: Path, sessions: tuple[Any, Any]
) -> None:
    """Pset 1's torque window is the station file's (20-27 Nm: 28 Nm is high, though the
    controller's own 20-30 Nm said OK); pset 2 has none there: the controller's (its
    0061's 100-250 Nm), also for a result fetched by id (0065 has no limits). Before: the
    station file's windows were only kept with the recording; a fetched result was not
    judged at all."""
    served, feeding = sessions
    with SpecController() as controller:
        heard = Listener(served, "op1", samples_from_batches=True)
        station_file = controller_station_file(
            tmp_path,
            controller.port,
            "tcp/127.0.0.1:1",
            [
                {"id": 1, "name": "cover", "torque_min_nm": 20.0, "torque_max_nm": 27.0},
                {"id": 2, "name": "flange"},
            ],
        )
        bridge = RunningBridge(station_file, feeding)
        try:
            assert controller.wait_subscribed(10.0, mids=(61,))
            controller.tighten(torque_nm=28.0, pset=1)
            controller.tighten(torque_nm=200.0, pset=2, torque_min_nm=100.0, torque_max_nm=250.0)
            wait_until(lambda: len(heard.of("results")) == 2, "two results")
            controller.drop()  # pset 2 again while the bridge is away: fetched by id
            controller.tighten(torque_nm=300.0, pset=2, torque_min_nm=100.0, torque_max_nm=250.0)
            wait_until(lambda: len(heard.of("results")) == 3, "the one fetched by id")
        finally:
            bridge.finish()
            heard.close()
    first, second, fetched = heard.of("results")
    assert (first.result, first.final_torque_nm.status) == ("NOK", "high")
    assert (first.final_torque_nm.min, first.final_torque_nm.max) == (20.0, 27.0)
    assert first.nok_reasons == (
        "the controller said OK, the windows NOK; torque high: 28 Nm, window 20 to 27 Nm"
    )
    assert (second.result, second.final_torque_nm.status) == ("OK", "ok")
    assert (second.final_torque_nm.min, second.final_torque_nm.max) == (100.0, 250.0)
    assert (fetched.program_name, fetched.final_torque_nm.status) == ("flange", "high")
    assert (fetched.final_torque_nm.min, fetched.final_torque_nm.max) == (100.0, 250.0)
    assert fetched.result == "NOK"
