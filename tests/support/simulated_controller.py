"""The simulated Open Protocol controller in a test: its station file, the controller
running in a thread, and a raw integrator over real TCP built on the codec (no mocks)."""

from __future__ import annotations

import contextlib
import socket
import threading
import time
from collections.abc import Iterator
from pathlib import Path

from services.rig.openprotocol.simulated_controller import SimulatedController
from shared.config import load_station
from shared.openprotocol import (
    CommandAccepted,
    CommandError,
    DataSubscribe,
    Frame,
    FrameReader,
    WireMessage,
    decode,
    encode,
    frame_bytes,
)
from tests.support.live_recorder import free_port
from tests.support.paths import CONFIG, STATION_FILE

FIRST_ID = 1000
TIMEOUT_S = 10.0


def write_controller_station(
    folder: Path,
    *,
    rig: dict[str, object] | None = None,
    section: dict[str, object] | None = None,
    pause_between_runs_s: float = 0.1,
) -> Path:
    """config/station.toml with an [openprotocol] section on a free loopback port and
    ``rig`` as its [rig.openprotocol] keys; runs 0.1 s apart."""
    text = STATION_FILE.read_text()
    text = text.replace('"joints/', f'"{CONFIG}/joints/').replace('"can/', f'"{CONFIG}/can/')
    text = text.replace('folder = "../recordings"', f'folder = "{folder / "recordings"}"')
    text = text.replace(
        "pause_between_runs_s = 0.3", f"pause_between_runs_s = {pause_between_runs_s}"
    )
    keys = {"host": "127.0.0.1", "port": free_port(), **(section or {})}
    text += "\n[openprotocol]\n" + "".join(f"{k} = {_toml(v)}\n" for k, v in keys.items())
    text += "\n[rig.openprotocol]\n" + "".join(
        f"{k} = {_toml(v)}\n" for k, v in (rig or {}).items()
    )
    path = folder / "station.toml"
    path.write_text(text)
    return path


def _toml(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    return repr(value)


@contextlib.contextmanager
def running_controller(
    station_path: Path,
    *,
    runs: int | None = None,
    program: int = 2,
    wait_for_integrator: bool = False,
) -> Iterator[SimulatedController]:
    """The controller serving in a thread (program 2: about 0.6 s a run) until the block ends."""
    station = load_station(station_path)
    controller = SimulatedController(
        station,
        station.config.program(program),
        first_tightening_id=FIRST_ID,
        seed=7,
        runs=runs,
        wait_for_integrator=wait_for_integrator,
    )
    stop = threading.Event()
    thread = threading.Thread(target=controller.run, args=(stop,), daemon=True)
    thread.start()
    try:
        yield controller
    finally:
        stop.set()
        thread.join(TIMEOUT_S)
        controller.close()
    assert not thread.is_alive(), "the controller did not stop"


class RawIntegrator:
    """An integrator as a test writes one: raw bytes on a real TCP socket, the codec's
    FrameReader on what comes back."""

    def __init__(self, port: int, *, connect_timeout_s: float = TIMEOUT_S) -> None:
        self.socket = socket.create_connection(("127.0.0.1", port), timeout=connect_timeout_s)
        self.reader = FrameReader()
        self._frames: list[Frame] = []

    def __enter__(self) -> RawIntegrator:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    def close(self) -> None:
        self.socket.close()

    def send(self, message: WireMessage, revision: int | None = None) -> None:
        self.send_bytes(encode(message, revision=revision))

    def send_bytes(self, data: bytes) -> None:
        self.socket.sendall(data)

    def send_frame(self, mid: int, data: bytes = b"", revision: int = 1) -> None:
        """A frame the codec would not write (a revision it lacks, content it refuses)."""
        self.send_bytes(frame_bytes(mid, data, revision=revision))

    def frame(self, timeout_s: float = TIMEOUT_S) -> Frame:
        """The next frame the controller sends (AssertionError when none comes in time)."""
        deadline = time.monotonic() + timeout_s
        while not self._frames:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise AssertionError(f"no message from the controller in {timeout_s} s")
            self.socket.settimeout(remaining)
            try:
                chunk = self.socket.recv(65536)
            except TimeoutError:
                continue
            if not chunk:
                raise AssertionError("the controller closed the link")
            self._frames += self.reader.feed(chunk)
        return self._frames.pop(0)

    def receive(self, timeout_s: float = TIMEOUT_S) -> object:
        return decode(self.frame(timeout_s))

    def expect(self, kind: type, timeout_s: float = TIMEOUT_S) -> object:
        """The next message, which must be a ``kind`` (keep-alives in between skipped)."""
        while True:
            message = self.receive(timeout_s)
            if type(message).__name__ == "KeepAlive" and kind.__name__ != "KeepAlive":
                continue
            assert isinstance(message, kind), f"expected {kind.__name__}, got {message}"
            return message

    def request(self, message: WireMessage, revision: int | None = None) -> object:
        """Send ``message`` and return the controller's answer."""
        self.send(message, revision)
        return self.receive()

    def accepted(self, message: WireMessage, revision: int | None = None) -> None:
        """The 0005 of ``message``: naming its MID, or for 0008 / 0009 the MID subscribed
        for (the specification's "accepted with the MID subscribed for")."""
        answer = self.request(message, revision)
        assert isinstance(answer, CommandAccepted), answer
        named = message.mid if isinstance(message, DataSubscribe) else message.MID
        assert answer.mid == named, answer

    def refused(self, message: WireMessage, revision: int | None = None) -> CommandError:
        answer = self.request(message, revision)
        assert isinstance(answer, CommandError), answer
        return answer

    def refusal(self) -> CommandError:
        answer = self.receive()
        assert isinstance(answer, CommandError), answer
        return answer

    def wait_closed(self, timeout_s: float = TIMEOUT_S) -> list[Frame]:
        """Read until the controller closes the link; the frames that came before."""
        deadline = time.monotonic() + timeout_s
        frames, self._frames = self._frames, []
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise AssertionError(f"the controller kept the link open for {timeout_s} s")
            self.socket.settimeout(remaining)
            try:
                chunk = self.socket.recv(65536)
            except TimeoutError:
                continue
            except ConnectionResetError:
                return frames
            if not chunk:
                return frames
            frames += self.reader.feed(chunk)
