"""The test Open Protocol controller, checked by a raw socket client written here.

The client writes each message by hand and checks byte positions against the tables of
the Open Protocol Specification R2.8.0 (1-based bytes there, 0-based slices here).
"""

from __future__ import annotations

import socket
import struct
from collections.abc import Iterator
from typing import Literal, NamedTuple

import pytest

from tests.support.openprotocol_controller import SpecController


def message(mid: int, data: str = "", revision: int = 1, no_ack: bool = False) -> bytes:
    body = data.encode("ascii")
    flag = "1" if no_ack else " "
    return f"{20 + len(body):04d}{mid:04d}{revision:03d}{flag}{' ' * 8}".encode() + body + b"\0"


class Client:
    """An integrator reduced to its socket: reads messages by their length."""

    def __init__(self, port: int) -> None:
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=2.0)
        self.buffer = b""

    def send(self, mid: int, data: str = "", revision: int = 1, no_ack: bool = False) -> None:
        self.sock.sendall(message(mid, data, revision, no_ack))

    def _fill(self, size: int) -> None:
        while len(self.buffer) < size:
            chunk = self.sock.recv(65536)
            if not chunk:
                raise ConnectionError("closed by the controller")
            self.buffer += chunk

    def read(self) -> bytes:
        """The next message, header included, without its NUL terminator."""
        self._fill(1)
        self.buffer = self.buffer.lstrip(b"\0")  # a MID 0900 may or may not end with NUL
        self._fill(4)
        length = int(self.buffer[:4])
        self._fill(length)
        raw, self.buffer = self.buffer[:length], self.buffer[length:]
        if raw[4:8] != b"0900":
            self._fill(1)
            assert self.buffer[:1] == b"\0", "an ASCII message ends with NUL"
            self.buffer = self.buffer[1:]
        return raw

    def expect(self, mid: int) -> bytes:
        raw = self.read()
        assert raw[4:8] == f"{mid:04d}".encode(), raw[:40]
        return raw

    def silent(self, wait_s: float = 0.15) -> bool:
        self.sock.settimeout(wait_s)
        try:
            return not self.buffer and not self.sock.recv(1, socket.MSG_PEEK)
        except TimeoutError:
            return True
        finally:
            self.sock.settimeout(2.0)

    def closed(self) -> bool:
        try:
            while True:
                if not self.sock.recv(65536):
                    return True
        except (TimeoutError, ConnectionError):
            return False

    def start(self, revision: int = 1) -> bytes:
        self.send(1, revision=revision)
        return self.expect(2)


@pytest.fixture
def controller() -> Iterator[SpecController]:
    with SpecController(ack_timeout_s=0.15, resends=2, link_timeout_s=2.0) as ctl:
        yield ctl
        assert ctl.faults == []


@pytest.mark.parametrize(("revision", "length"), [(1, 57), (2, 62), (3, 125)])
def test_the_session_starts_with_0001_and_nothing_is_answered_before(
    controller: SpecController, revision: int, length: int
) -> None:
    client = Client(controller.port)
    client.send(60)
    client.send(9999)
    assert client.silent()
    reply = client.start(revision)
    assert int(reply[:4]) == len(reply) == length  # Tables 11-13
    assert reply[8:11] == f"{revision:03d}".encode()
    assert reply[20:30] == b"0100010201"
    assert reply[30:57] == b"03" + b"PF6000-EMU".ljust(25)
    client.send(1)
    assert client.expect(4)[20:26] == b"000196"
    assert controller.errors_sent == [(1, 96)]


def test_a_start_revision_above_the_maximum_is_refused_with_97(
    controller: SpecController,
) -> None:
    client = Client(controller.port)
    client.send(1, revision=4)
    assert client.expect(4)[20:26] == b"000197"
    assert client.start(3)[8:11] == b"003"


@pytest.mark.parametrize(("names", "named"), [("subscribed", b"0900"), ("subscribing", b"0008")])
def test_the_0005_answering_0008_names_the_mid_the_setting_says(
    names: Literal["subscribed", "subscribing"], named: bytes
) -> None:
    with SpecController(accept_names=names) as ctl:
        client = Client(ctl.port)
        client.start()
        client.send(8, "0900001" + "38" + "0" + " " * 29 + "02001002")
        assert client.expect(5)[20:24] == named
        client.send(8, "1201001000")
        assert client.expect(4)[20:26] == (b"1201" if names == "subscribed" else b"0008") + b"73"
        assert ctl.subscriptions == {900: 1}


def test_a_result_not_acknowledged_is_resent_then_the_link_dropped(
    controller: SpecController,
) -> None:
    client = Client(controller.port)
    client.start()
    client.send(60, revision=2)
    client.expect(5)
    tightening_id = controller.tighten(torque_nm=25.0)
    first = client.expect(61)
    assert first[8:11] == b"002" and len(first) == 385  # Table 59
    assert first[181:189] == b"24002500"  # torque: bytes 182-189
    assert first[301:313] == f"41{tightening_id:010d}".encode()  # tightening id: 302-313
    assert [client.expect(61) for _ in range(2)] == [first, first]
    assert client.closed()
    assert controller.delivered_ids == []
    assert "unacknowledged" in controller.link_ends[-1]


def test_results_queue_and_go_one_at_a_time_after_each_0062() -> None:
    with SpecController() as controller:  # acknowledgements awaited 5 s: no re-send here
        client = Client(controller.port)
        client.start()
        client.send(60)
        client.expect(5)
        ids = [controller.tighten(torque_nm=21.5, angle_deg=123), controller.tighten()]
        first = client.expect(61)
        assert len(first) == 231  # Table 76, revision 1
        assert first[138:146] == b"15002150" and first[167:174] == b"1900123"  # torque, angle
        assert first[219:231] == f"23{ids[0]:010d}".encode()
        assert client.silent()
        client.send(62)
        assert client.expect(61)[219:231] == f"23{ids[1]:010d}".encode()
        client.send(62)
        assert controller.wait_for(lambda: controller.delivered_ids == ids)
        assert controller.acks == [62, 62]


def test_a_no_ack_subscription_gets_every_result_at_once(controller: SpecController) -> None:
    client = Client(controller.port)
    client.start()
    client.send(60, no_ack=True)
    client.expect(5)
    controller.tighten()
    controller.tighten()
    assert [client.expect(61)[219:231] for _ in range(2)] == [b"230000000001", b"230000000002"]


def test_old_results_by_id_newest_unknown_and_revision_too_high(
    controller: SpecController,
) -> None:
    for torque_nm in (20.5, 22.5, 24.5):
        controller.tighten(torque_nm=torque_nm, push=False)
    client = Client(controller.port)
    client.start()
    client.send(64, "0000000002", revision=2)
    reply = client.expect(65)
    assert len(reply) == 226 and reply[8:11] == b"002"  # Table 86
    assert reply[20:32] == b"010000000002" and reply[132:140] == b"19002250"
    client.send(64, "0000000000")
    reply = client.expect(65)
    assert len(reply) == 118 and reply[20:32] == b"010000000003"  # Table 85
    assert reply[79:87] == b"08002450"
    client.send(64, "0000000099", revision=2)
    assert client.expect(4)[20:26] == b"006415"
    client.send(64, "0000000001", revision=3)
    assert client.expect(4)[20:26] == b"006497"
    assert controller.old_result_requests == [(2, 2), (0, 1), (99, 2), (1, 3)]
    assert controller.delivered_ids == [2, 3]


class Trace(NamedTuple):
    tightening_id: int
    trace_type: int
    unit: int
    period_ms: float
    samples: list[float]


def parse_trace(raw: bytes, order: str) -> Trace:
    """A MID 0900 read by Table 157, its samples decoded in byte order `order` (> or <)."""
    assert int(raw[:4]) == len(raw)  # the length counts the NUL and the binary part
    ascii_part, _, binary = raw[20:].partition(b"\0")
    text = ascii_part.decode()
    assert text[29:32] == "000"  # no PIDs common to all traces
    trace_type, unit, pos = int(text[32:34]), int(text[36:39]), 39
    pids: dict[str, str] = {}
    for _ in range(int(text[pos : pos + 3])):
        pid, length = text[pos + 3 : pos + 8], int(text[pos + 8 : pos + 11])
        pids[pid] = text[pos + 20 : pos + 20 + length]
        pos += 17 + length
    pos += 3
    assert text[pos : pos + 3] == "001"  # one resolution field
    first, last = int(text[pos + 3 : pos + 8]), int(text[pos + 8 : pos + 13])
    time_length, time_unit = int(text[pos + 13 : pos + 16]), text[pos + 18 : pos + 21]
    period_ms = float(text[pos + 21 : pos + 21 + time_length])
    count = int(text[pos + 21 + time_length :])
    assert (first, last, time_unit, len(binary)) == (0, count - 1, "202", 2 * count)
    scale = float(pids["02214"]) if "02214" in pids else 1 / float(pids["02213"])
    samples = [s * scale for s in struct.unpack(f"{order}{count}h", binary)]
    return Trace(int(text[:10]), trace_type, unit, period_ms, samples)


@pytest.mark.parametrize(("byte_order", "scaling"), [("big", "coefficient"), ("little", "divisor")])
def test_traces_in_either_byte_order_peak_at_the_final_torque(
    byte_order: Literal["big", "little"], scaling: Literal["coefficient", "divisor"]
) -> None:
    with SpecController(trace_byte_order=byte_order, scaling=scaling) as ctl:
        client = Client(ctl.port)
        client.start()
        client.send(8, "0900001" + "38" + "0" + " " * 29 + "02001002")
        client.expect(5)
        tightening_id = ctl.tighten(torque_nm=31.25, angle_deg=200)
        order, wrong = (">", "<") if byte_order == "big" else ("<", ">")
        raws = [client.expect(900) for _ in range(2)]
        angle, torque = (parse_trace(raw, order) for raw in raws)
        for _ in raws:
            client.send(5, "0900")
        assert (angle.trace_type, angle.unit, torque.trace_type, torque.unit) == (1, 50, 2, 1)
        assert angle.tightening_id == torque.tightening_id == tightening_id
        assert torque.period_ms == pytest.approx(1.0)
        assert 300 <= len(torque.samples) == len(angle.samples) <= 1000
        assert max(torque.samples) == pytest.approx(31.25) == torque.samples[-1]
        assert angle.samples[-1] == pytest.approx(200.0) == max(angle.samples)
        assert max(parse_trace(raws[1], wrong).samples) != pytest.approx(31.25)
        assert ctl.wait_for(lambda: ctl.trace_acks == [(tightening_id, 1), (tightening_id, 2)])


def test_a_restart_cuts_the_link_and_numbers_results_from_1_again(
    controller: SpecController,
) -> None:
    assert [controller.tighten(push=False) for _ in range(3)] == [1, 2, 3]
    client = Client(controller.port)
    client.start()
    controller.restart()
    assert client.closed()
    client = Client(controller.port)
    client.start()
    client.send(64, "0000000002")
    assert client.expect(4)[20:26] == b"006415"
    assert controller.tighten(push=False) == 1
    assert controller.connections == 2


@pytest.mark.parametrize("mode", ["whole", "coalesced", "bytewise", "random"])
def test_every_write_mode_gives_whole_messages_to_a_reader_of_lengths(
    mode: Literal["whole", "coalesced", "bytewise", "random"],
) -> None:
    with SpecController(write_mode=mode, seed=7) as ctl:
        client = Client(ctl.port)
        client.start(3)
        ctl.raise_alarm("E404", "tool overheated")
        client.send(70, revision=2)
        if mode == "coalesced":  # the 0005 and the 0076 after it went in one send
            client.sock.settimeout(2.0)
            assert client.sock.recv(65536, socket.MSG_PEEK).count(b"\0") == 2
        assert client.expect(5)[20:24] == b"0070"
        status = client.expect(76)
        assert len(status) == 57 and status[20:30] == b"0110" + b"2E404 "  # Table 99
        client.send(77)
        client.send(60, revision=2)
        client.send(8, "0900001" + "35" + "0" + " " * 29 + "01002")
        assert [client.expect(5)[20:24] for _ in range(2)] == [b"0060", b"0900"]
        tightening_id = ctl.tighten(torque_nm=12.34)
        assert client.expect(61)[181:189] == b"24001234"
        torque = parse_trace(client.expect(900), ">")
        assert max(torque.samples) == pytest.approx(12.34)
        client.send(62)
        client.send(5, "0900")
        ctl.clear_alarm()
        assert client.expect(74)[20:24] == b"E404"
        client.send(75)
        assert ctl.wait_for(lambda: ctl.acks == [77, 62, 5, 75])
        assert ctl.delivered_ids == [tightening_id] and ctl.protocol_errors == []


def test_alarms_pushed_as_0071_in_revision_1_and_2(controller: SpecController) -> None:
    client = Client(controller.port)
    client.start()
    client.send(70)
    client.expect(5)
    assert client.expect(76)[20:23] == b"010"  # no alarm active
    controller.raise_alarm("E851", "torque transducer")
    alarm = client.expect(71)
    assert len(alarm) == 53 and alarm[20:32] == b"01E851021031"  # Table 95
    client.send(72)
    client.send(73)
    client.expect(5)
    client.send(70, revision=2)
    client.expect(5)
    client.expect(76)
    controller.raise_alarm("E1021", "drive hot")
    alarm = client.expect(71)
    assert alarm[20:27] == b"01E1021" and alarm[54:56] == b"05"  # Table 96
    assert alarm[56:106] == b"drive hot".ljust(50)
    client.send(70, revision=3)
    assert client.expect(4)[20:26] == b"007011"


def test_tool_data_at_the_revision_asked_and_97_above(controller: SpecController) -> None:
    client = Client(controller.port)
    client.start()
    client.send(40)
    assert len(client.expect(41)) == 81  # Table 63
    client.send(40, revision=2)
    reply = client.expect(41)
    assert len(reply) == 156 and reply[122:126] == b"0804"  # Table 64: tool type
    client.send(40, revision=6)
    assert client.expect(4)[20:26] == b"004097"
    assert controller.tool_data_revisions == [1, 2, 6]


def test_keep_alive_is_mirrored_and_a_silent_link_is_closed() -> None:
    with SpecController(link_timeout_s=0.3) as ctl:
        client = Client(ctl.port)
        client.start()
        client.send(9999)
        assert client.read() == message(9999)[:-1]
        client.send(1234)
        assert client.expect(4)[20:26] == b"123499"
        assert client.closed()
        assert ctl.link_ends == ["nothing heard for 0.3 s"]
    with SpecController(mirror_keep_alive=False) as ctl:
        client = Client(ctl.port)
        client.start()
        client.send(9999)
        assert client.silent()


def test_0003_is_accepted_and_ends_the_link(controller: SpecController) -> None:
    client = Client(controller.port)
    client.start()
    client.send(3)
    assert client.expect(5)[20:24] == b"0003"
    assert client.closed()
    assert controller.stops == 1


def test_hostile_wires_are_framed_with_the_fields_replaced(controller: SpecController) -> None:
    tightening_id = controller.tighten(push=False)
    wire = controller.result_wire(tightening_id, 2, replace={24: "", 41: "x" * 12})
    assert int(wire[:4]) == len(wire) - 1 == 385 - 6 + 2 and wire.endswith(b"\0")
    assert b"002425" in wire and b"41xxxxxxxxxxxx42" in wire
    count = len(controller.curves[tightening_id].torque_nm)
    bare = controller.trace_wire(tightening_id, 2, resolution=False)
    assert bare[: bare.index(b"\0")].endswith(f"000{count:05d}".encode())
    assert int(bare[:4]) == len(bare)
    huge = controller.trace_wire(tightening_id, 2, time_value="1e300", nul_separator=False)
    assert b"00100000" + f"{count - 1:05d}".encode() + b"00503202" + b"1e300" in huge
    assert int(huge[:4]) == len(huge) == len(bare) + 18 + 5 - 1


def test_the_controller_reads_any_split_of_the_integrators_stream(
    controller: SpecController,
) -> None:
    client = Client(controller.port)
    for byte in message(1, revision=2):
        client.sock.send(bytes([byte]))
    client.expect(2)
    client.sock.sendall(message(40) + message(9999) + message(40, revision=2))
    assert [client.read()[4:8] for _ in range(3)] == [b"0041", b"9999", b"0041"]
    client.sock.sendall(b"00x0garbage")
    assert client.closed()
    assert controller.link_ends == ["unreadable stream"]
    assert controller.protocol_errors == ["unreadable length b'00x0'"]


def test_generic_subscriptions_stand_for_0060_and_end_with_0009(
    controller: SpecController,
) -> None:
    client = Client(controller.port)
    client.start()
    client.send(8, "0061002000")
    assert client.expect(5)[20:24] == b"0061"
    controller.tighten()
    assert len(client.expect(61)) == 385  # revision 2, as the MID 0008 asked
    client.send(62)
    client.send(8, "0900001" + "38" + "0" + " " * 29 + "02001002")
    client.expect(5)
    client.send(9, "0900001" + "05" + "01001")
    assert client.expect(5)[20:24] == b"0900"
    assert controller.wait_for(lambda: controller.subscriptions == {61: 2, 900: 1})
    client.send(9, "0061001000")
    client.expect(5)
    controller.tighten()
    assert len(client.expect(900)) > 600 and client.silent()  # the torque trace, no result
    client.send(9, "0900001" + "05" + "01001")
    assert client.expect(4)[20:26] == b"090072"
    client.send(8, "0061003000")
    assert client.expect(4)[20:26] == b"006174"
