"""Put frames, good and bad, on a station's ``udp_multicast`` CAN bus, and watch for stops.

:class:`CanInjector` plays the tool controller and the force sensor node
frame by frame (contract frames encoded through the station DBC) and the
faults a real bus sees: unknown ids, wrong lengths, remote and error frames,
and datagrams on the bus's group that are no CAN frame at all. It keeps a
ledger of what it sent, by kind, so a test can compare the acquisition's
counters with it. :class:`StopListener` records every ``StopCommand`` frame
on the bus with its receive time. :class:`Pacer` keeps a 1 kHz schedule on
absolute deadlines.
"""

from __future__ import annotations

import socket
import struct
import threading
import time
from collections import Counter
from dataclasses import dataclass
from types import TracebackType

import can

from shared.config import CanSection
from shared.contract import COUNTER_MODULO, StationDatabase, ToolRunState
from shared.runtime import open_bus


class CanInjector:
    """Sends frames on the station bus (a context manager; closes its bus and socket)."""

    def __init__(self, section: CanSection, database: StationDatabase) -> None:
        if section.interface != "udp_multicast" or section.port is None:
            raise ValueError("the injector needs a udp_multicast bus with a port")
        self.database = database
        self.sent: Counter[str] = Counter()  # kind -> frames (or datagrams) sent
        self._bus = open_bus(section)
        self._group = (section.channel, section.port)
        self._raw = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._raw.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, struct.pack("@I", 1))

    # -- contract frames -----------------------------------------------------------------

    def tool_status(
        self, run_id: int, state: ToolRunState | int, tool_id: int = 7, program_id: int = 1
    ) -> None:
        """ToolStatus; an int ``state`` outside :class:`ToolRunState` is a corrupt frame."""
        signals: dict[str, float | int] = {
            "RunId": run_id,
            "ToolId": tool_id,
            "ProgramId": program_id,
            "State": int(state),
        }
        self._send("tool_status", self.database.tool_status_id, "ToolStatus", signals)

    def tool_sensors(self, counter: int, torque_nm: float, angle_deg: float) -> None:
        signals = {"Torque": torque_nm, "Angle": angle_deg, "Counter": counter % COUNTER_MODULO}
        self._send("tool_sensors", self.database.tool_sensors_id, "ToolSensors", signals)

    def joint_sensors(self, counter: int, force_n: float) -> None:
        signals = {"Force": force_n, "Counter": counter % COUNTER_MODULO}
        self._send("joint_sensors", self.database.joint_sensors_id, "JointSensors", signals)

    # -- faults --------------------------------------------------------------------------

    def unknown_id(self, arbitration_id: int, length: int = 8) -> None:
        """A frame of an id the DBC does not know (another node's traffic, or noise)."""
        if arbitration_id in self.database.by_id:
            raise ValueError(f"0x{arbitration_id:x} is a contract id")
        self._frame("unknown_id", can.Message(arbitration_id=arbitration_id, data=bytes(length)))

    def wrong_length(self, name: str, length: int) -> None:
        """A frame with a contract id but ``length`` data bytes instead of the DBC's."""
        frame_id = {v[0]: k for k, v in self.database.by_id.items()}[name]
        if length == self.database.by_id[frame_id][1]:
            raise ValueError(f"{name} is {length} bytes long: not a wrong length")
        self._frame("wrong_length", can.Message(arbitration_id=frame_id, data=bytes(length)))

    def remote_frame(self, arbitration_id: int) -> None:
        message = can.Message(arbitration_id=arbitration_id, is_remote_frame=True, dlc=0)
        self._frame("remote_frame", message)

    def error_frame(self) -> None:
        self._frame("error_frame", can.Message(is_error_frame=True, dlc=0))

    def garbage_datagram(self, payload: bytes = b"\xc1 not a CAN frame") -> None:
        """A datagram on the bus's group and port that does not unpack into a CAN frame."""
        self._raw.sendto(payload, self._group)
        self.sent["garbage_datagram"] += 1

    # -- plumbing ------------------------------------------------------------------------

    @property
    def frames(self) -> int:
        """CAN frames sent so far (garbage datagrams are not frames)."""
        return sum(n for kind, n in self.sent.items() if kind != "garbage_datagram")

    def _send(self, kind: str, frame_id: int, name: str, signals: dict[str, float | int]) -> None:
        message = can.Message(
            arbitration_id=frame_id,
            data=self.database.encode(name, signals),
            is_extended_id=self.database.is_extended(name),
        )
        self._frame(kind, message)

    def _frame(self, kind: str, message: can.Message) -> None:
        self._bus.send(message)
        self.sent[kind] += 1

    def close(self) -> None:
        self._raw.close()
        self._bus.shutdown()

    def __enter__(self) -> CanInjector:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()


@dataclass(frozen=True, slots=True)
class HeardStop:
    run_id: int
    reason: int
    received_ns: int  # kernel receive time on the listening socket


class StopListener:
    """Records every ``StopCommand`` frame on the bus, from a thread (a context manager)."""

    def __init__(
        self, section: CanSection, database: StationDatabase, spindles: int = 1, stride: int = 2
    ) -> None:
        """``spindles``, ``stride``: a multi-spindle station's (each spindle's StopCommand at
        the DBC's id plus its stride); every spindle's is heard."""
        self._database = database
        self._bus = open_bus(section)
        self._bus.set_filters(
            [
                {
                    "can_id": database.stop_command_id + k * stride,
                    "can_mask": 0x7FF,
                    "extended": False,
                }
                for k in range(spindles)
            ]
        )
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self._heard: list[HeardStop] = []
        self._arrived = threading.Condition(self._lock)
        self._thread = threading.Thread(target=self._listen, name="stop-listener", daemon=True)
        self._thread.start()

    @property
    def heard(self) -> list[HeardStop]:
        with self._lock:
            return list(self._heard)

    def wait_for(self, count: int, timeout_s: float) -> list[HeardStop]:
        """Wait until ``count`` stops were heard (or ``timeout_s`` passed); returns them all."""
        deadline = time.monotonic() + timeout_s
        with self._arrived:
            while len(self._heard) < count and (left := deadline - time.monotonic()) > 0:
                self._arrived.wait(left)
            return list(self._heard)

    def _listen(self) -> None:
        while not self._stop.is_set():
            try:
                message = self._bus.recv(0.05)
            except can.CanError:
                continue  # a garbage datagram: not ours to count
            if message is None or message.is_error_frame:
                continue
            received_ns = round(message.timestamp * 1e9)
            try:
                signals = self._database.decode_named("StopCommand", message.data)
                heard = HeardStop(int(signals["RunId"]), int(signals["Reason"]), received_ns)
            except Exception:  # a malformed StopCommand is still a stop to report
                heard = HeardStop(-1, -1, received_ns)
            with self._arrived:
                self._heard.append(heard)
                self._arrived.notify_all()

    def close(self) -> None:
        if not self._stop.is_set():
            self._stop.set()
            self._thread.join()
            self._bus.shutdown()

    def __enter__(self) -> StopListener:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()


class Pacer:
    """Absolute 1 ms deadlines (``time.perf_counter``); never drifts, may run late."""

    def __init__(self, period_s: float = 1e-3) -> None:
        self._period_s = period_s
        self._next = time.perf_counter()

    def wait(self) -> None:
        self._next += self._period_s
        left = self._next - time.perf_counter()
        if left > 0:
            time.sleep(left)
