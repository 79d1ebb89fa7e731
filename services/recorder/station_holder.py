"""One recorder per station: a second one refuses at start, in one line naming the first.

Two recorders of one station write the same run files: names taken twice,
messages not recorded, files left broken. So the line's recorder holds two
things, and a second one is refused (:class:`~shared.errors.ConfigError`, exit
status 2) when either is held already:

- the recordings folder's lock (``<recordings>/.recorder.lock``, an ``flock``
  the kernel drops when the holder dies, whatever kills it): the file says who
  holds it (pid, host, since when), so the refusal names it. Taken before
  anything else, it also makes the recorder that finishes a crash's unfinished
  files (:func:`~shared.recordings.mcap.finish_unfinished`) the only writer of
  the folder;
- the station's liveliness token ``boltwatch/<station>/health/recorder`` on
  the line, asked for before this recorder declares its own: a recorder on
  another host, writing another folder, holds it.

A ``--view-only`` recorder is a live view beside the line's recorder: it holds
neither and is refused by neither.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import socket
from collections.abc import Iterable, Iterator
from datetime import UTC, datetime
from pathlib import Path

import zenoh

from shared.contract import keys
from shared.errors import ConfigError

LOCK_NAME = ".recorder.lock"
#: how long to ask the line whether another recorder already holds a station
PEER_CHECK_TIMEOUT_S = 1.0


@contextlib.contextmanager
def recordings_folder_held(folder: Path) -> Iterator[None]:
    """Hold ``folder``'s recorder lock until the context ends (or the process dies);
    ConfigError naming the holder when another process holds it."""
    path = folder / LOCK_NAME
    try:
        handle = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
    except OSError as err:
        raise ConfigError(f"{path}: the recorder's lock cannot be opened: {err.strerror}") from err
    try:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError as err:
            raise ConfigError(
                f"{folder}: held by another recorder ({_holder(handle) or 'holder unknown'}, "
                f"{path}); one recorder writes a recordings folder: stop it first, or give "
                "this one --view-only"
            ) from err
        since = datetime.now(UTC).isoformat(timespec="seconds")
        holder = f"pid {os.getpid()} on {socket.gethostname()} since {since}\n"
        os.ftruncate(handle, 0)
        os.pwrite(handle, holder.encode(), 0)
        yield
    finally:
        os.close(handle)  # the lock goes with the descriptor; the file stays for the next


def _holder(handle: int) -> str:
    with contextlib.suppress(OSError):
        return os.pread(handle, 200, 0).decode(errors="replace").strip()
    return ""


def refuse_stations_recorded_elsewhere(session: zenoh.Session, station_ids: Iterable[str]) -> None:
    """ConfigError naming the first station of ``station_ids`` whose recorder's liveliness
    token is alive on the line."""
    wanted = set(station_ids)
    replies = session.liveliness().get(
        keys.health_key("*", "recorder"), timeout=PEER_CHECK_TIMEOUT_S
    )
    held = sorted(
        str(reply.ok.key_expr)
        for reply in replies
        if reply.ok is not None and keys.split_key(str(reply.ok.key_expr))[0] in wanted
    )
    if held:
        stations = ", ".join(keys.split_key(key)[0] for key in held)
        raise ConfigError(
            f"station(s) {stations} already have a recorder on the line ({held[0]} is alive); "
            "one recorder records a station: stop it first, or give this one --view-only"
        )
