"""A small Open Protocol controller on loopback for the bridge's tests: a real TCP server.

Built on the codec (``shared.openprotocol``), one connection at a time, in a
thread. It does what the bridge needs a controller to do, as real ones do:
0001 -> 0002 (0004 error 97 above ``start_revision``), 0060 (0004 97 above
``result_revision``), 0008, 0070 -> 0005; 0040 -> 0041; 9999 mirrored (or not:
``mirror``); 0064 -> 0065 by id (id 0: the newest; an unknown id: 0004 15);
0003 ends the link. :meth:`tighten` stores a result (ids count up) and, to a
subscribed integrator, pushes its 0061 and its torque and angle 0900. Tests
also push raw bytes (:meth:`send_raw`) and cut the link (:meth:`drop`).
"""

from __future__ import annotations

import contextlib
import socket
import threading
from dataclasses import dataclass, field

from shared.openprotocol import (
    AlarmSubscribe,
    CommandAccepted,
    CommandError,
    CommunicationStart,
    CommunicationStartAck,
    CommunicationStop,
    DataSubscribe,
    FrameReader,
    KeepAlive,
    LastTighteningResult,
    OldResultRequest,
    OldTighteningResult,
    ResultAcknowledge,
    ResultSubscribe,
    ToolData,
    ToolDataRequest,
    TraceCurve,
    TraceType,
    decode,
    encode,
)

TIMESTAMP = "2026-11-24:10:00:00"
SAMPLES = 400


def torque_curve(samples: int = SAMPLES, peak_nm: float = 200.0) -> tuple[float, ...]:
    """A ramp to ``peak_nm`` (200 Nm) with a few stick-slip drops of 3 % of it."""
    drop = 0.03 * peak_nm
    return tuple(
        round(peak_nm * i / samples - (drop if i % 50 > 42 else 0.0), 1) for i in range(samples)
    )


@dataclass
class StoredResult:
    tightening_id: int
    torque: tuple[float, ...]
    angle: tuple[float, ...]
    ok: bool = True


@dataclass
class TcpController:
    name: str = "TestController"
    start_revision: int = 3
    result_revision: int = 2
    mirror: bool = True
    port: int = 0  # 0: any free port
    timestamp: str = TIMESTAMP  # of every result and curve (the controller's clock)
    next_id: int = 1
    results: dict[int, StoredResult] = field(default_factory=dict)
    acks: int = 0
    connections: int = 0
    stops: int = 0
    keep_alives: int = 0
    #: the pset's final torque target and window (MID 0061), and where its curves end
    torque_target_nm: float = 200.0
    torque_window_nm: tuple[float, float] = (180.0, 240.0)

    def __post_init__(self) -> None:
        self._server = socket.create_server(("127.0.0.1", self.port))
        self.port = int(self._server.getsockname()[1])
        self._server.settimeout(0.1)
        self._lock = threading.Lock()
        self._client: socket.socket | None = None
        self._subscribed_revision: int | None = None
        self._traces = False
        self._closed = threading.Event()
        self.connected = threading.Event()
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._thread.start()

    # -- what tests do ---------------------------------------------------------------

    def result_bytes(self, tightening_id: int) -> bytes:
        """The 0061 of a stored result at the subscribed revision, as it goes on the wire."""
        with self._lock:
            revision = self._subscribed_revision or 1
            return encode(self._result(self.results[tightening_id]), revision=revision)

    def tighten(
        self, ok: bool = True, push: bool = True, drop_after_first_curve: bool = False
    ) -> int:
        """A new tightening: stored, and pushed (result and curves) to a subscriber."""
        with self._lock:
            tightening_id = self.next_id
            self.next_id += 1
            stored = StoredResult(
                tightening_id,
                torque_curve(peak_nm=self.torque_target_nm),
                tuple(round(0.1 * i, 1) for i in range(SAMPLES)),
                ok,
            )
            self.results[tightening_id] = stored
            if push and self._client is not None and self._subscribed_revision is not None:
                if self._traces:
                    self._send(self._curve(stored, TraceType.ANGLE))
                if drop_after_first_curve:
                    self._close_client()
                    return tightening_id
                self._send(self._result(stored), revision=self._subscribed_revision)
                if self._traces:
                    self._send(self._curve(stored, TraceType.TORQUE))
        return tightening_id

    @property
    def traces_subscribed(self) -> bool:
        with self._lock:
            return self._traces and self._client is not None

    def send_raw(self, data: bytes) -> None:
        with self._lock:
            if self._client is not None:
                self._client.sendall(data)

    def drop(self) -> None:
        """Cut the link (the integrator sees it closed)."""
        with self._lock:
            self._close_client()

    def close(self) -> None:
        self._closed.set()
        self.drop()
        self._server.close()
        self._thread.join(timeout=5.0)

    # -- the server --------------------------------------------------------------------

    def _serve(self) -> None:
        while not self._closed.is_set():
            try:
                client, _ = self._server.accept()
            except (TimeoutError, OSError):
                continue
            with self._lock:
                self._close_client()
                self._client = client
                self._subscribed_revision = None
                self._traces = False
                self.connections += 1
            self.connected.set()
            self._read(client)

    def _read(self, client: socket.socket) -> None:
        reader = FrameReader()
        client.settimeout(0.1)
        while not self._closed.is_set():
            try:
                chunk = client.recv(65536)
            except TimeoutError:
                continue
            except OSError:
                return
            if not chunk:
                with self._lock:
                    if self._client is client:
                        self._close_client()
                return
            for frame in reader.feed(chunk):
                with self._lock:
                    if self._client is not client:
                        return
                    self._answer(decode(frame), frame.revision)

    def _answer(self, message: object, revision: int) -> None:
        if isinstance(message, CommunicationStart):
            if revision > self.start_revision:
                self._send(CommandError(mid=1, error_code=97))
            else:
                ack = CommunicationStartAck(
                    cell_id=1,
                    channel_id=1,
                    controller_name=self.name,
                    supplier_code="BWT",
                    open_protocol_version="2.0",
                    controller_software_version="1.0",
                    tool_software_version="1.0",
                    revision=revision,
                )
                self._send(ack, revision=min(revision, 3))
        elif isinstance(message, ResultSubscribe):
            if revision > self.result_revision:
                self._send(CommandError(mid=60, error_code=97))
            else:
                self._subscribed_revision = revision
                self._send(CommandAccepted(mid=60))
        elif isinstance(message, DataSubscribe):
            self._traces = True
            self._send(CommandAccepted(mid=8))
        elif isinstance(message, AlarmSubscribe):
            self._send(CommandAccepted(mid=70))
        else:
            self._answer_request(message)

    def _answer_request(self, message: object) -> None:
        if isinstance(message, ToolDataRequest):
            self._send(
                ToolData(
                    tool_serial="SIM-3",
                    tightenings=len(self.results),
                    last_calibration="2026-01-02:03:04:05",
                    controller_serial="CTRL-1",
                    revision=1,
                )
            )
        elif isinstance(message, KeepAlive):
            self.keep_alives += 1
            if self.mirror:
                self._send(KeepAlive())
        elif isinstance(message, OldResultRequest):
            wanted = message.tightening_id or max(self.results, default=0)
            stored = self.results.get(wanted)
            if stored is None:
                self._send(CommandError(mid=64, error_code=15))
            else:
                self._send(self._old_result(stored))
        elif isinstance(message, ResultAcknowledge):
            self.acks += 1
        elif isinstance(message, CommunicationStop):
            self.stops += 1
            self._close_client()

    def _send(self, message: object, revision: int | None = None) -> None:
        if self._client is None:
            return
        try:
            self._client.sendall(encode(message, revision=revision))  # type: ignore[arg-type]
        except OSError:
            self._close_client()

    def _close_client(self) -> None:
        if self._client is not None:
            with contextlib.suppress(OSError):
                self._client.shutdown(socket.SHUT_RDWR)
            self._client.close()
            self._client = None
            self._subscribed_revision = None

    # -- messages ----------------------------------------------------------------------

    def _result(self, stored: StoredResult) -> LastTighteningResult:
        revision = self._subscribed_revision or 1
        extra: dict[str, object] = {}
        if revision >= 2:
            extra = {
                "strategy": 1,
                "strategy_options": 0,
                "rundown_angle_status": 1,
                "current_monitoring_status": 1,
                "selftap_status": 1,
                "prevail_torque_monitoring_status": 1,
                "prevail_torque_compensate_status": 1,
                "tightening_error_status": 0,
                "rundown_angle_min_deg": 0,
                "rundown_angle_max_deg": 0,
                "rundown_angle_deg": 0,
                "current_monitoring_min_pct": 0,
                "current_monitoring_max_pct": 0,
                "current_monitoring_pct": 0,
                "selftap_min_nm": 0.0,
                "selftap_max_nm": 0.0,
                "selftap_torque_nm": 0.0,
                "prevail_torque_min_nm": 0.0,
                "prevail_torque_max_nm": 0.0,
                "prevail_torque_nm": 0.0,
                "job_sequence_number": 0,
                "sync_tightening_id": 0,
                "tool_serial": "SIM-3",
            }
        return LastTighteningResult(
            cell_id=1,
            channel_id=1,
            controller_name=self.name,
            vin=f"VIN{stored.tightening_id:04d}",
            job_id=0,
            pset_id=1,
            batch_size=10,
            batch_counter=stored.tightening_id % 10,
            tightening_ok=stored.ok,
            batch_status=1,  # type: ignore[arg-type]
            torque_status=1,  # type: ignore[arg-type]
            angle_status=1,  # type: ignore[arg-type]
            torque_min_nm=self.torque_window_nm[0],
            torque_max_nm=self.torque_window_nm[1],
            torque_final_target_nm=self.torque_target_nm,
            torque_nm=stored.torque[-1],
            angle_min_deg=0,
            angle_max_deg=90,
            angle_final_target_deg=0,
            angle_deg=int(stored.angle[-1]),
            tightening_id=stored.tightening_id,
            timestamp=self.timestamp,
            pset_changed=self.timestamp,
            revision=revision,
            **extra,  # type: ignore[arg-type]
        )

    def _old_result(self, stored: StoredResult) -> OldTighteningResult:
        return OldTighteningResult(
            tightening_id=stored.tightening_id,
            vin=f"VIN{stored.tightening_id:04d}",
            pset_id=1,
            batch_counter=stored.tightening_id % 10,
            tightening_ok=stored.ok,
            batch_status=1,  # type: ignore[arg-type]
            torque_status=1,  # type: ignore[arg-type]
            angle_status=1,  # type: ignore[arg-type]
            torque_nm=stored.torque[-1],
            angle_deg=int(stored.angle[-1]),
            timestamp=self.timestamp,
        )

    def _curve(self, stored: StoredResult, kind: TraceType) -> TraceCurve:
        values = stored.torque if kind == TraceType.TORQUE else stored.angle
        return TraceCurve.build(
            result_id=stored.tightening_id,
            timestamp=self.timestamp,
            trace_type=int(kind),
            unit=1 if kind == TraceType.TORQUE else 50,
            samples=values,
            time_step_s=0.001,
            coefficient=0.1,
        )
