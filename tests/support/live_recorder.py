"""Test helpers around a live recorder: a recorder in a thread, station files on loopback,
free ports, a publisher of runs, waiting for a condition.

Used by the recorder's, the predictor's and the system tests, the fuzz and the
benchmarks; no product code imports it.
"""

from __future__ import annotations

import threading
import time
import tomllib
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import zenoh

from services.recorder.service import RecorderService
from shared.config import AnyStation, ControllerStation, LoadedStation, toml_writer
from shared.contract import encode, keys
from shared.runtime import ServiceSkeleton
from tests.support.free_ports import free_tcp_port
from tests.support.paths import STATION_FILE

WAIT_S = 10.0  # upper bound on waits for zenoh; tests never assert on time


def wait_until(condition: Callable[[], bool], what: str, timeout_s: float = WAIT_S) -> None:
    """Poll ``condition`` until true; AssertionError naming ``what`` after ``timeout_s``."""
    deadline = time.monotonic() + timeout_s
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"gave up waiting for {what}")
        time.sleep(0.01)


def has_subscribers(publisher: zenoh.Publisher) -> bool:
    """Whether a subscriber matches ``publisher`` somewhere.

    zenoh 1.10's stubs type ``matching_status`` as bool, but it returns a
    MatchingStatus object, which is always truthy: read its ``matching``.
    """
    status: Any = publisher.matching_status
    return bool(getattr(status, "matching", status))


def publish(session: zenoh.Session, items: Sequence[tuple[str, Any]], station: str = "st1") -> int:
    """Put every ``(topic, message)`` on ``boltwatch/<station>/<topic>`` in order, once a
    subscriber matches each topic, none dropped (BLOCK); a bytes message goes as it is."""
    publishers = {
        topic: session.declare_publisher(
            keys.station_key(station, topic), congestion_control=zenoh.CongestionControl.BLOCK
        )
        for topic in {topic for topic, _ in items}
    }
    wait_until(lambda: all(has_subscribers(p) for p in publishers.values()), "the recorder")
    for topic, message in items:
        publishers[topic].put(message if isinstance(message, bytes) else encode(message))
    for publisher in publishers.values():
        publisher.undeclare()
    return len(items)


class RunningRecorder:
    """A RecorderService working in a thread of this process, as ServiceRunner runs it."""

    def __init__(self, loaded: AnyStation | Sequence[AnyStation]) -> None:
        first = loaded if isinstance(loaded, LoadedStation | ControllerStation) else loaded[0]
        self.skeleton = ServiceSkeleton("recorder")
        self.session = self.skeleton.open_session(first.config.zenoh)
        self.service = RecorderService(loaded, self.skeleton)
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self.service.work, args=(self.stop,))
        self.thread.start()

    def finish(self) -> None:
        """Stop as on SIGTERM (stop flag + wake), then the skeleton's stop; safe to call
        twice."""
        if self.thread.is_alive():
            self.stop.set()
            self.service.wake()
            self.thread.join(WAIT_S)
            if self.thread.is_alive():
                raise AssertionError("the recorder did not stop")
        self.skeleton.close()


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on right now, and that the kernel hands to
    no other process meanwhile (:mod:`tests.support.free_ports`)."""
    return free_tcp_port()


def write_station_file(
    path: Path,
    recordings: Path,
    listen: Sequence[str] = (),
    connect: Sequence[str] = (),
    recorder: Mapping[str, Any] | None = None,
    quality: Mapping[str, Any] | None = None,
    retention: Mapping[str, Any] | None = None,
    station: Mapping[str, Any] | None = None,
    zenoh: Mapping[str, Any] | None = None,
) -> Path:
    """A copy of config/station.toml as a zenoh peer on the given endpoints.

    ``can.dbc`` and ``station.joint`` point at the repository's files;
    ``recorder.folder`` is ``recordings``; ``recorder`` overrides recorder keys,
    ``station`` station keys, ``zenoh`` zenoh keys (``mode``, ``lease_s``);
    ``quality``: the ``[quality]`` section; ``retention``: the ``[retention]`` section.
    """
    with STATION_FILE.open("rb") as handle:
        data = tomllib.load(handle)
    base = STATION_FILE.parent
    data["station"] = {**data["station"], **(station or {})}
    data["station"]["joint"] = str((base / data["station"]["joint"]).resolve())
    data["can"]["dbc"] = str((base / data["can"]["dbc"]).resolve())
    data["zenoh"] = {
        "mode": "peer",
        "connect": list(connect),
        "listen": list(listen),
        **(zenoh or {}),
    }
    data["recorder"] = {**data["recorder"], "folder": str(recordings), **(recorder or {})}
    if quality is not None:
        data["quality"] = dict(quality)
    if retention is not None:
        data["retention"] = dict(retention)
    path.write_text(toml_writer.dumps(data))
    return path
