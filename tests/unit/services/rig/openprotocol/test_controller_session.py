"""The simulated Open Protocol controller's session over real TCP: start, revisions,
refusals, keep-alive, stop, a silent link, a TCP read split anywhere."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from services.rig.openprotocol.controller_server import MAX_LINKS
from shared.openprotocol import (
    CommandAccepted,
    CommunicationStart,
    CommunicationStartAck,
    CommunicationStop,
    DataSubscribe,
    DataUnsubscribe,
    ErrorCode,
    KeepAlive,
    OldResultRequest,
    ResultSubscribe,
    ResultUnsubscribe,
    ToolData,
    ToolDataRequest,
    encode,
    trace_extra_data,
)
from tests.support.simulated_controller import (
    RawIntegrator,
    running_controller,
    write_controller_station,
)


def started(port: int, revision: int = 1) -> RawIntegrator:
    integrator = RawIntegrator(port)
    answer = integrator.request(CommunicationStart(revision=revision))
    assert isinstance(answer, CommunicationStartAck), answer
    return integrator


@pytest.mark.parametrize("revision", [1, 2, 3])
def test_start_is_acknowledged_at_the_revision_asked(tmp_path: Path, revision: int) -> None:
    with (
        running_controller(write_controller_station(tmp_path)) as controller,
        RawIntegrator(controller.server.port) as integrator,
    ):
        integrator.send(CommunicationStart(revision=revision))
        frame = integrator.frame()
        assert (frame.mid, frame.revision) == (2, revision)
        ack = CommunicationStartAck.from_data(frame.data, revision)
        assert ack.controller_name == "boltwatch sim st1"
        assert (ack.supplier_code is not None) == (revision >= 2)
        assert (ack.controller_software_version is not None) == (revision == 3)


def test_revisions_not_spoken_are_refused_with_error_97(tmp_path: Path) -> None:
    station = write_controller_station(tmp_path, rig={"max_result_revision": 1})
    with running_controller(station) as controller:
        with RawIntegrator(controller.server.port) as integrator:
            integrator.send_frame(1, revision=4)
            refusal = integrator.refusal()
            assert (refusal.mid, refusal.error_code) == (1, ErrorCode.MID_REVISION_UNSUPPORTED)
            assert isinstance(integrator.request(CommunicationStart()), CommunicationStartAck)
            # an older controller: 0061 at revision 1 only (0060's header revision asks it)
            refusal = integrator.refused(ResultSubscribe(revision=2))
            assert (refusal.mid, refusal.error_code) == (60, 97)
            integrator.send_frame(60, revision=3)  # beyond what the codec has at all
            assert integrator.refusal().error_code == 97
            refusal = integrator.refused(OldResultRequest(tightening_id=0, revision=2))
            assert (refusal.mid, refusal.error_code) == (64, 97)
            integrator.accepted(ResultSubscribe(revision=1))
            # a second subscription is refused (error 9), an unsubscription taken once
            assert integrator.refused(ResultSubscribe(revision=1)).error_code == 9
            integrator.accepted(ResultUnsubscribe())
            assert integrator.refused(ResultUnsubscribe()).error_code == 10
            # 0900 through 0008: a revision the codec lacks (74), a MID it does not push (73)
            refusal = integrator.refused(DataSubscribe(mid=900, wanted_revision=2))
            assert (refusal.mid, refusal.error_code) == (8, 74)
            assert integrator.refused(DataSubscribe(mid=61)).error_code == 73
            integrator.accepted(DataSubscribe(mid=900, extra_data=trace_extra_data([2])))
            assert integrator.refused(DataSubscribe(mid=900)).error_code == 71
            integrator.accepted(DataUnsubscribe(mid=900))
            assert integrator.refused(DataUnsubscribe(mid=900)).error_code == 72
        assert controller.state.counters.errors_sent == 10


def test_unknown_mids_and_bad_content_are_refused_and_the_link_goes_on(tmp_path: Path) -> None:
    with running_controller(write_controller_station(tmp_path)) as controller:
        with started(controller.server.port) as integrator:
            integrator.send_frame(18, b"001")  # 0018 select pset: not spoken
            refusal = integrator.refusal()
            assert (refusal.mid, refusal.error_code) == (18, ErrorCode.UNKNOWN_MID)
            # 0002 is what a controller sends, not what it takes
            integrator.send(CommunicationStartAck(cell_id=1, channel_id=1, controller_name="x"))
            assert integrator.refusal().error_code == ErrorCode.UNKNOWN_MID
            # 0064 whose tightening id is not a number: invalid data (1), counted
            integrator.send_frame(64, b"00000000A1")
            assert integrator.refusal().error_code == ErrorCode.INVALID_DATA
            assert isinstance(integrator.request(KeepAlive()), KeepAlive)
        assert controller.state.counters.bad_messages == 1


def test_nothing_but_0001_is_answered_before_the_session_starts(tmp_path: Path) -> None:
    with (
        running_controller(write_controller_station(tmp_path)) as controller,
        RawIntegrator(controller.server.port) as integrator,
    ):
        integrator.send(KeepAlive())
        integrator.send(ResultSubscribe())
        answer = integrator.request(CommunicationStart())
        assert isinstance(answer, CommunicationStartAck)  # the first answer of all
        assert integrator.refused(CommunicationStart()).error_code == 96


def test_keep_alive_is_mirrored_or_not_as_set(tmp_path: Path) -> None:
    with (
        running_controller(write_controller_station(tmp_path)) as controller,
        started(controller.server.port) as integrator,
    ):
        assert isinstance(integrator.request(KeepAlive()), KeepAlive)
    station = write_controller_station(tmp_path, rig={"mirror_keep_alive": False})
    with running_controller(station) as controller:
        with started(controller.server.port) as integrator:
            integrator.send(KeepAlive())
            answer = integrator.request(ToolDataRequest(revision=2))
            assert isinstance(answer, ToolData)  # the keep-alive got no answer before it
        assert controller.state.counters.keep_alives == 1


def test_tool_data_names_the_simulated_tool(tmp_path: Path) -> None:
    station = write_controller_station(tmp_path, rig={"last_service": "2026-03-01"})
    with (
        running_controller(station) as controller,
        started(controller.server.port) as integrator,
    ):
        data = integrator.request(ToolDataRequest(revision=2))
        assert isinstance(data, ToolData)
        assert data.tool_serial == "SIM-7" and data.tightenings == 0
        assert data.last_service == "2026-03-01:00:00:00"
        assert data.calibration_value_nm == 320.0


def test_0003_is_accepted_and_ends_the_link(tmp_path: Path) -> None:
    with running_controller(write_controller_station(tmp_path)) as controller:
        with started(controller.server.port) as integrator:
            integrator.send(CommunicationStop())
            frames = integrator.wait_closed()
            assert [(f.mid, f.data) for f in frames] == [(5, b"0003")]
        assert controller.state.counters.drops_stopped == 1


def test_a_silent_link_is_dropped_and_a_kept_alive_one_is_not(tmp_path: Path) -> None:
    station = write_controller_station(
        tmp_path, rig={"link_timeout_s": 0.6}, section={"keep_alive_s": 0.2}
    )
    with running_controller(station) as controller:
        with started(controller.server.port) as silent, started(controller.server.port) as alive:
            began = time.monotonic()
            while time.monotonic() - began < 1.5:  # well past the silent one's drop
                assert isinstance(alive.request(KeepAlive()), KeepAlive)
                time.sleep(0.2)
            silent.wait_closed(timeout_s=0.1)  # already closed
            assert isinstance(alive.request(KeepAlive()), KeepAlive)
        assert controller.state.counters.drops_silent == 1


def test_a_tcp_read_may_end_anywhere(tmp_path: Path) -> None:
    """Messages split byte by byte, then several in one write, garbage before one."""
    with running_controller(write_controller_station(tmp_path)) as controller:
        with RawIntegrator(controller.server.port) as integrator:
            stream = encode(CommunicationStart(revision=2)) + encode(ToolDataRequest())
            for index in range(len(stream)):
                integrator.send_bytes(stream[index : index + 1])
                time.sleep(0.002)
            assert isinstance(integrator.receive(), CommunicationStartAck)
            assert isinstance(integrator.receive(), ToolData)
            burst = b"\xff\x13garbage" + encode(KeepAlive()) + encode(ToolDataRequest())
            integrator.send_bytes(burst[:7])
            time.sleep(0.05)
            integrator.send_bytes(burst[7:31])
            time.sleep(0.05)
            integrator.send_bytes(burst[31:])
            assert isinstance(integrator.receive(), KeepAlive)
            assert isinstance(integrator.receive(), ToolData)
        assert controller.state.counters.garbage_bytes == 9


def test_integrators_beyond_the_limit_are_turned_away(tmp_path: Path) -> None:
    with running_controller(write_controller_station(tmp_path)) as controller:
        port = controller.server.port
        integrators = [started(port) for _ in range(MAX_LINKS)]
        with RawIntegrator(port) as extra:
            extra.wait_closed()
        for integrator in integrators:
            assert isinstance(integrator.request(KeepAlive()), KeepAlive)
            integrator.close()
        assert controller.state.counters.links_refused == 1


def test_0005_of_a_trace_is_taken_silently(tmp_path: Path) -> None:
    with (
        running_controller(write_controller_station(tmp_path)) as controller,
        started(controller.server.port) as integrator,
    ):
        integrator.send(CommandAccepted(mid=900))
        assert isinstance(integrator.request(KeepAlive()), KeepAlive)
