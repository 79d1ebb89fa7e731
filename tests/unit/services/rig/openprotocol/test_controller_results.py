"""The simulated Open Protocol controller's results over real TCP: push and acknowledge,
three re-sends then a drop, results kept while nobody is connected and served by id,
curves, alarms."""

from __future__ import annotations

from pathlib import Path

import pytest

from shared.openprotocol import (
    UNIT_DEGREE,
    UNIT_NM,
    Alarm,
    AlarmStatus,
    AlarmSubscribe,
    CommunicationStart,
    CommunicationStartAck,
    DataSubscribe,
    ErrorCode,
    KeepAlive,
    LastTighteningResult,
    OldResultRequest,
    OldTighteningResult,
    ResultAcknowledge,
    ResultSubscribe,
    TraceCurve,
    TraceType,
    ValueStatus,
    decode,
    timestamp_ns,
    trace_extra_data,
)
from tests.support.live_recorder import wait_until
from tests.support.simulated_controller import (
    FIRST_ID,
    RawIntegrator,
    running_controller,
    write_controller_station,
)


def subscribed(port: int, *, revision: int = 2, traces: bool = False) -> RawIntegrator:
    integrator = RawIntegrator(port)
    assert isinstance(integrator.request(CommunicationStart()), CommunicationStartAck)
    if traces:
        extra = trace_extra_data([TraceType.ANGLE, TraceType.TORQUE])
        integrator.accepted(DataSubscribe(mid=900, extra_data=extra))
    integrator.accepted(ResultSubscribe(revision=revision))
    return integrator


def test_each_result_is_pushed_with_its_curves_and_the_next_waits_for_the_ack(
    tmp_path: Path,
) -> None:
    station = write_controller_station(tmp_path, rig={"batch_size": 2})
    with running_controller(station, wait_for_integrator=True) as controller:
        with subscribed(controller.server.port, traces=True) as integrator:
            results = []
            for _ in range(3):
                angle = integrator.expect(TraceCurve)
                torque = integrator.expect(TraceCurve)
                result = integrator.expect(LastTighteningResult)
                assert isinstance(result, LastTighteningResult)
                assert isinstance(angle, TraceCurve) and isinstance(torque, TraceCurve)
                assert result.revision == 2 and result.pset_id == 2
                assert (angle.trace_type, angle.unit) == (TraceType.ANGLE, UNIT_DEGREE)
                assert (torque.trace_type, torque.unit) == (TraceType.TORQUE, UNIT_NM)
                assert angle.result_id == torque.result_id == result.tightening_id
                assert torque.time_step_s == 0.001 and len(torque.samples) > 500
                assert len(angle.samples) == len(torque.samples)
                # the result's final torque is the curve's peak (hundredths of Nm on the wire)
                assert abs(max(torque.samples) - result.torque_nm) < 0.02
                run_s = len(torque.samples) * torque.time_step_s
                ended_s = timestamp_ns(result.timestamp) / 1e9
                assert 0 <= ended_s - timestamp_ns(torque.timestamp) / 1e9 <= run_s + 1
                results.append(result)
                integrator.send(ResultAcknowledge())
            wait_until(lambda: controller.state.counters.results_acked == 3, "3 results acked", 5.0)
        ids = [r.tightening_id for r in results]
        assert ids == [FIRST_ID, FIRST_ID + 1, FIRST_ID + 2]
        # program 2 has no windows: the hard limits are the windows, every run OK
        for result in results:
            assert result.tightening_ok and result.torque_status == ValueStatus.OK
            assert (result.torque_min_nm, result.torque_max_nm) == (0.0, 320.0)
            assert result.vin == f"SIM{result.tightening_id:010d}"
            assert result.tool_serial == "SIM-7"
        assert [(r.batch_counter, r.batch_size) for r in results] == [(1, 2), (2, 2), (1, 2)]
        assert [r.batch_status for r in results] == [0, 1, 0]


def test_an_unacknowledged_result_is_sent_three_times_more_then_the_link_dropped(
    tmp_path: Path,
) -> None:
    station = write_controller_station(
        tmp_path, rig={"ack_timeout_s": 0.3}, pause_between_runs_s=30.0
    )
    with running_controller(station, wait_for_integrator=True) as controller:
        with subscribed(controller.server.port, revision=1) as integrator:
            frames = integrator.wait_closed(timeout_s=10.0)
        sent = [decode(f) for f in frames if f.mid == 61]
        assert len(sent) == 4  # the push and three re-sends, then the drop
        assert {r.tightening_id for r in sent} == {FIRST_ID}  # type: ignore[union-attr]
        counters = controller.state.counters
        assert (counters.results_resent, counters.drops_ack) == (3, 1)
        # the subscription ended with the link; the result is kept, served by id
        with RawIntegrator(controller.server.port) as again:
            again.request(CommunicationStart())
            old = again.request(OldResultRequest(tightening_id=FIRST_ID, revision=2))
            assert isinstance(old, OldTighteningResult) and old.tightening_id == FIRST_ID
            assert old.revision == 2 and old.batch_size == 10


@pytest.mark.parametrize("ack_revision", [1, 6])
def test_an_acknowledged_result_is_not_sent_again(tmp_path: Path, ack_revision: int) -> None:
    """0062 at revision 6 is what OpenProtocolInterpreter's ``new Mid0062()`` writes. Before:
    refused with error 97, the result sent again three times, then the link dropped."""
    station = write_controller_station(
        tmp_path, rig={"ack_timeout_s": 0.3}, pause_between_runs_s=30.0
    )
    with running_controller(station, wait_for_integrator=True) as controller:
        with subscribed(controller.server.port) as integrator:
            integrator.expect(LastTighteningResult)
            integrator.send_frame(ResultAcknowledge.MID, b"", revision=ack_revision)
            for _ in range(5):  # 1.5 s of keep-alives: no result comes again
                assert isinstance(integrator.request(KeepAlive()), KeepAlive)
                integrator.socket.settimeout(0.3)
        assert controller.state.counters.results_resent == 0


def test_results_are_kept_while_nobody_is_connected_and_served_by_id(tmp_path: Path) -> None:
    station = write_controller_station(tmp_path, rig={"results_kept": 2})
    with running_controller(station, runs=3) as controller:
        # the tool works alone, at its own pace
        wait_until(lambda: controller.state.counters.tightenings == 3, "3 tightenings", 20.0)
        with RawIntegrator(controller.server.port) as integrator:
            integrator.request(CommunicationStart())
            newest = integrator.request(OldResultRequest(tightening_id=0))
            assert isinstance(newest, OldTighteningResult)
            assert newest.tightening_id == FIRST_ID + 2 and newest.revision == 1
            kept = integrator.request(OldResultRequest(tightening_id=FIRST_ID + 1))
            assert isinstance(kept, OldTighteningResult) and kept.tightening_id == FIRST_ID + 1
            # the oldest is beyond the bound of 2, the next never was: error 15 both
            for unknown in (FIRST_ID, FIRST_ID + 3):
                refusal = integrator.refused(OldResultRequest(tightening_id=unknown))
                assert (refusal.mid, refusal.error_code) == (64, 15)
                assert refusal.error_code == ErrorCode.TIGHTENING_ID_NOT_FOUND
        assert controller.state.store.forgotten == 1


def test_a_run_on_a_hard_limit_is_nok_and_raises_an_alarm(tmp_path: Path) -> None:
    """Program 2 with 0.3 s of cycle time ends on the time limit: NOK, alarm E104."""
    station = write_controller_station(tmp_path, pause_between_runs_s=30.0)
    station.write_text(station.read_text().replace("max_time_s = 4.0", "max_time_s = 0.3"))
    with running_controller(station, wait_for_integrator=True) as controller:
        with subscribed(controller.server.port) as integrator:
            integrator.accepted(AlarmSubscribe(revision=2))
            status = integrator.expect(AlarmStatus)
            assert isinstance(status, AlarmStatus) and not status.alarm_active
            result = integrator.expect(LastTighteningResult)
            alarm = integrator.expect(Alarm)
            assert isinstance(result, LastTighteningResult) and not result.tightening_ok
            assert result.tightening_error_status == 1
            assert isinstance(alarm, Alarm) and alarm.error_code == "E104"
            assert alarm.revision == 2 and alarm.alarm_text is not None
            assert "time limit" in alarm.alarm_text
            # a new subscriber hears that the alarm is active
            with subscribed(controller.server.port) as other:
                other.accepted(AlarmSubscribe())
                status = other.expect(AlarmStatus)
                assert isinstance(status, AlarmStatus)
                assert status.alarm_active and status.error_code == "E104"
        assert controller.state.counters.alarms == 1
